//! An eight-wide BVH: the binary SAH tree ([`super::Bvh`]) collapsed so that each node holds
//! the boxes of up to eight children in structure-of-arrays lanes, tested against a ray in one
//! AVX2 pass where the CPU has it and in two SSE halves elsewhere ([`super::Isa`], chosen at
//! run time), as Embree's BVH8 does. A ray then visits about a third as many nodes as in the
//! binary tree.
//!
//! Below the top [`TOP_LEVELS`] levels, child boxes are quantised to 8 bits per coordinate on a
//! grid spanning the node's box (Embree's compressed nodes, Ylitie et al. 2017), so a node is
//! 128 bytes, two cache lines, about half of what full-precision boxes take. The top levels'
//! nodes ([`TopNode`], at most 73 of them) keep their children's boxes in floats: every ray
//! tests the root, and an incoherent ray makes most of its visits within these levels, so their
//! test skips the decoding for the price of a few kilobytes. The grid rounds every box
//! outwards, with each coordinate checked after rounding against the decoding the traversal
//! does (`origin + q * step`, the same two operations), so a decoded box always contains the
//! exact one: a ray can visit a few more nodes, never miss one. The slab test on the boxes is
//! [`Aabb::hit`](crate::geometry::Aabb::hit)'s, lane by lane (entry and exit sides chosen by the
//! direction's sign), with the reciprocal direction kept finite.

use super::Tally;
use super::bvh::Node;
use super::simd::{Isa, Lanes8, baseline::Halves};
use crate::geometry::BvhRay;
use glam::Vec3A;
use rayon::prelude::*;
use std::mem::MaybeUninit;

pub mod packet;

/// A child reference: an interior node's index, or, when [`LEAF`] is set, a leaf's payload in
/// the bits below it (its index in the leaves [`WideBvh::collapse`] returns).
pub type ChildRef = u32;
/// Set in a [`ChildRef`] that is a leaf.
pub const LEAF: u32 = 1 << 31;
/// Set in a [`ChildRef`] to an interior node of the top levels: its index in
/// [`WideBvh::top`] is in the bits below (other interior references index [`WideBvh::nodes`]).
/// Tested after [`LEAF`], whose payloads may use this bit.
pub const TOP: u32 = 1 << 30;

/// Levels of the tree, from the root, whose nodes are [`TopNode`]s: with up to eight children
/// each, at most 1 + 8 + 64 = 73 nodes, 18.7 KB. Over the displaced spheres of `rtis bench`
/// (10k to 1M triangles), 1M incoherent rays make 1.72 to 1.76 visits a ray in these levels, of
/// 2.07 to 2.73 in all (measured).
pub const TOP_LEVELS: u32 = 3;
/// An unused child slot, which no ray enters.
pub const EMPTY: ChildRef = u32::MAX;

/// A child's box as the traversal tests it, smallest and largest corner (`None` for an unused
/// slot).
pub type ChildBox = Option<(glam::Vec3, glam::Vec3)>;

/// Children per node.
pub const WIDTH: usize = 8;

/// Eight child boxes in floats, one per lane, and their references: a node of the top levels
/// ([`TOP_LEVELS`]), 256 bytes. An unused slot's box is empty (its smallest side above its
/// largest).
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct TopNode {
    /// `sides[axis][0][slot]` and `sides[axis][1][slot]`: the smallest and the largest
    /// coordinate on `axis` of each child's box (the node test reads a side by its index).
    pub sides: [[[f32; WIDTH]; 2]; 3],
    /// The children; unused slots are [`EMPTY`].
    pub child: [ChildRef; WIDTH],
}

/// Eight child boxes, one per lane, on the node's 8-bit grid, and their references.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct WideNode {
    /// The grid's origin: the smallest corner of the node's box.
    pub origin: [f32; 3],
    /// The grid's step per axis (0 on an axis where the node's box is flat).
    pub step: [f32; 3],
    /// `sides[axis][0][slot]` and `sides[axis][1][slot]`: the smallest and the largest
    /// coordinate on `axis` of each child's box, in steps from the origin (laid out as
    /// [`TopNode::sides`], so that the node test finds a side by its index).
    pub sides: [[[u8; WIDTH]; 2]; 3],
    /// The children; unused slots are [`EMPTY`].
    pub child: [ChildRef; WIDTH],
}

/// The grid coordinates of `[lo, hi]` on the grid `origin + q * step`, rounded outwards: the
/// decoded interval contains `[lo, hi]`, which lies within `[origin, origin + 255 step]`, and
/// is the tightest that does (the largest `q` decoding to at most `lo`, the smallest decoding to
/// at least `hi`). `inv_step` is `1 / step`, computed once per node: the estimate it gives can
/// be a step off near a grid line, and the decoding checks that follow correct it. (On x86-64
/// the build runs [`quantize_all`], the same steps in lanes; this is its reference.)
#[cfg(any(test, not(target_arch = "x86_64")))]
fn quantize(lo: f32, hi: f32, origin: f32, step: f32, inv_step: f32) -> (u8, u8) {
    let decode = |q: u8| origin + q as f32 * step;
    if step == 0.0 {
        return (0, 0);
    }
    // `lo - origin` is at least 0, so truncation is the floor (a call to `floorf` on baseline
    // x86-64, which has no rounding instruction).
    let mut ql = ((lo - origin) * inv_step).clamp(0.0, 255.0) as u8;
    while ql > 0 && decode(ql) > lo {
        ql -= 1;
    }
    while ql < 255 && decode(ql + 1) <= lo {
        ql += 1;
    }
    let x = ((hi - origin) * inv_step).clamp(0.0, 255.0);
    let mut qh = x as u8 + ((x as u8 as f32) < x) as u8;
    while qh < 255 && decode(qh) < hi {
        qh += 1;
    }
    while qh > 0 && decode(qh - 1) >= hi {
        qh -= 1;
    }
    debug_assert!(decode(ql) <= lo && decode(qh) >= hi, "box outside its grid");
    (ql, qh)
}

/// [`quantize`] of the intervals `lo[k]..hi[k]` for `k < n` on one grid, the others left 0:
/// with SSE2, four intervals per pass, each lane taking the steps `quantize` takes (the same
/// operations, the corrections repeated while any lane needs one), so the grid coordinates are
/// the same; a node's eight children cost about what two of them cost one by one.
fn quantize_all(
    lo: &[f32; WIDTH],
    hi: &[f32; WIDTH],
    n: usize,
    (origin, step, inv_step): (f32, f32, f32),
) -> ([u8; WIDTH], [u8; WIDTH]) {
    let (mut ql, mut qh) = ([0u8; WIDTH], [0u8; WIDTH]);
    if step == 0.0 {
        return (ql, qh);
    }
    #[cfg(target_arch = "x86_64")]
    for half in 0..WIDTH / 4 {
        let k = 4 * half;
        if k >= n {
            break;
        }
        let four = |v: &[f32; WIDTH]| -> [f32; 4] { std::array::from_fn(|j| v[k + j]) };
        // SAFETY: SSE2 is in the x86-64 baseline.
        let (l, h) = unsafe { quantize4(&four(lo), &four(hi), origin, step, inv_step) };
        for j in k..n.min(k + 4) {
            (ql[j], qh[j]) = (l[j - k] as u8, h[j - k] as u8);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    for k in 0..n {
        (ql[k], qh[k]) = quantize(lo[k], hi[k], origin, step, inv_step);
    }
    // What `quantize` asserts: each decoded interval contains its box.
    for k in 0..n {
        let decode = |q: u8| origin + q as f32 * step;
        debug_assert!(
            decode(ql[k]) <= lo[k] && decode(qh[k]) >= hi[k],
            "box outside its grid"
        );
    }
    (ql, qh)
}

/// [`quantize`] in the four SSE lanes (see [`quantize_all`]); the grid coordinates as `i32`.
///
/// # Safety
/// Needs SSE2 (the x86-64 baseline).
#[cfg(target_arch = "x86_64")]
#[inline]
unsafe fn quantize4(
    lo: &[f32; 4],
    hi: &[f32; 4],
    origin: f32,
    step: f32,
    inv: f32,
) -> ([i32; 4], [i32; 4]) {
    use std::arch::x86_64::*;
    /// Step the lanes where `moves` holds (its mask is -1 there) one grid line up (or down),
    /// until it holds in none.
    #[inline(always)]
    fn walk(mut q: __m128i, up: bool, moves: impl Fn(__m128i) -> __m128i) -> __m128i {
        // SAFETY: SSE2 is in the x86-64 baseline; these only compute on registers.
        unsafe {
            loop {
                let m = moves(q);
                if _mm_movemask_epi8(m) == 0 {
                    return q;
                }
                q = if up {
                    _mm_sub_epi32(q, m)
                } else {
                    _mm_add_epi32(q, m)
                };
            }
        }
    }
    // SAFETY: the caller's; the loads read the four floats of each array.
    unsafe {
        let (lo, hi) = (_mm_loadu_ps(lo.as_ptr()), _mm_loadu_ps(hi.as_ptr()));
        let (o, s, inv) = (_mm_set1_ps(origin), _mm_set1_ps(step), _mm_set1_ps(inv));
        let (zero, one, top) = (_mm_setzero_si128(), _mm_set1_epi32(1), _mm_set1_epi32(255));
        let decode = |q: __m128i| _mm_add_ps(o, _mm_mul_ps(_mm_cvtepi32_ps(q), s));
        // `x.clamp(0.0, 255.0)` then the truncation of `as u8`: `maxps` returns its second
        // operand for a NaN, which `as u8` makes 0, and for two zeros, which truncate alike.
        let estimate = |v: __m128| {
            let x = _mm_mul_ps(_mm_sub_ps(v, o), inv);
            _mm_min_ps(_mm_max_ps(x, _mm_setzero_ps()), _mm_set1_ps(255.0))
        };
        let (is, holds) = (_mm_castps_si128, _mm_and_si128);
        let ql = _mm_cvttps_epi32(estimate(lo));
        let ql = walk(ql, false, |q| {
            holds(_mm_cmpgt_epi32(q, zero), is(_mm_cmpgt_ps(decode(q), lo)))
        });
        let ql = walk(ql, true, |q| {
            let next = decode(_mm_add_epi32(q, one));
            holds(_mm_cmplt_epi32(q, top), is(_mm_cmple_ps(next, lo)))
        });
        // `x as u8`, plus one where that is below `x`.
        let x = estimate(hi);
        let t = _mm_cvttps_epi32(x);
        let qh = _mm_sub_epi32(t, is(_mm_cmplt_ps(_mm_cvtepi32_ps(t), x)));
        let qh = walk(qh, true, |q| {
            holds(_mm_cmplt_epi32(q, top), is(_mm_cmplt_ps(decode(q), hi)))
        });
        let qh = walk(qh, false, |q| {
            let before = decode(_mm_sub_epi32(q, one));
            holds(_mm_cmpgt_epi32(q, zero), is(_mm_cmpge_ps(before, hi)))
        });
        let (mut l, mut h) = ([0i32; 4], [0i32; 4]);
        _mm_storeu_si128(l.as_mut_ptr() as *mut __m128i, ql);
        _mm_storeu_si128(h.as_mut_ptr() as *mut __m128i, qh);
        (l, h)
    }
}

/// The step of a 255-step grid from `lo` that reaches `hi`.
fn grid_step(lo: f32, hi: f32) -> f32 {
    if hi <= lo {
        return 0.0;
    }
    // The extent over 255, within an ulp or two; divided first when the extent overflows.
    let extent = hi - lo;
    let mut step = if extent.is_finite() {
        extent / 255.0
    } else {
        hi / 255.0 - lo / 255.0
    };
    // Raised until the grid reaches: a few ulps at most, then doubling, so an extent of one
    // ulp (where the estimate can round to 0) costs a handful of steps, not a count to 2^-31.
    let mut raised = 0;
    while lo + 255.0 * step < hi {
        step = if raised < 8 {
            step.next_up()
        } else {
            (2.0 * step).max(f32::MIN_POSITIVE)
        };
        raised += 1;
    }
    step
}

/// The wide hierarchy; `top[0]` is the root (both arrays are empty when the scene has no
/// finite primitive).
#[derive(Clone, Debug, Default)]
pub struct WideBvh {
    /// The nodes of the top [`TOP_LEVELS`] levels, root first, in depth-first order.
    pub top: Vec<TopNode>,
    /// The nodes below, in depth-first order.
    pub nodes: Vec<WideNode>,
    /// The instruction set the traversals run ([`Isa::detect`] unless
    /// [`WideBvh::set_isa`] chose another).
    isa: Isa,
}

/// Ask the CPU to bring every cache line of the `T` at `x` into its caches, so that a miss on
/// it overlaps with the work done before it is read. Does nothing where no prefetch instruction
/// is known. `x` need not point at a `T`: a prefetch never faults.
#[inline(always)]
pub fn prefetch<T>(x: *const T) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_MM_HINT_T0, _mm_prefetch};
        // SAFETY: a prefetch is a hint: it never faults, whatever the address, and changes no
        // state the program can observe.
        let line =
            |at: usize| unsafe { _mm_prefetch::<_MM_HINT_T0>((x as *const i8).wrapping_add(at)) };
        // A byte every 64 from the first, and the last: one in every cache line the `T`
        // touches (a 160-byte block at 48 mod 64 spans four), a fixed count, no loop left.
        let size = std::mem::size_of::<T>();
        let mut at = 0;
        while at < size {
            line(at);
            at += 64;
        }
        // Not needed where every `T` starts a line and fills whole ones (the nodes), nor for a
        // `T` of no bytes.
        if size > 0 && (!size.is_multiple_of(64) || !std::mem::align_of::<T>().is_multiple_of(64)) {
            line(size - 1);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = x;
}

/// A ray splatted across the eight lanes of a node test.
#[derive(Clone, Copy)]
struct RayBox<L> {
    o: [L; 3],
    /// The origin as the exit sides' distances take it: `o`, except on an axis the ray runs
    /// parallel to (`1 / d` infinite), where it is moved one ulp away from the exit side, so
    /// that an origin exactly on that side (a ray along a box's face) gets a large exit
    /// distance, as the exact one is infinite, instead of `0 * MAX = 0`, which dropped the
    /// box of a triangle whose edge the ray runs through (`tests/integration/batch.rs`).
    /// An origin outside the slab by one ulp then enters it: a visit, never a hit.
    o_exit: [L; 3],
    inv_d: [L; 3],
    /// `inv_d` raised by `1 + 4 eps` in magnitude (and kept finite): a positive exit distance
    /// it gives is not below the exact one, whatever the rounding of the four operations that
    /// make it (`1 / d`, the raise, the subtraction, the product), so the test never drops a
    /// box the ray grazes. (Where `|1 / d|` is within 4 ulps of `f32::MAX`, the clamp takes
    /// the margin back: a direction component below 3e-39, whose exits lie beyond 1e38 anyway.)
    inv_exit: [L; 3],
    /// `back[axis]` is 1 if the ray runs towards smaller coordinates on that axis (the sign
    /// bit of its reciprocal direction): it then enters a slab by its largest side, else 0.
    back: [usize; 3],
}

impl<L: Lanes8> RayBox<L> {
    /// The ray's origin and reciprocal direction, an infinite reciprocal (a direction parallel
    /// to an axis) replaced by the largest float of its sign: `0 * inf` would be NaN where the
    /// origin lies on a box's side, while `0 * MAX` is 0 and keeps the ray in the slab, on every
    /// platform. Otherwise only an origin outside a slab by less than about `1 / MAX` in a
    /// parallel direction enters it, which costs a visit, never a hit.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn new(o: Vec3A, inv_d: Vec3A) -> Self {
        let finite = |v: Vec3A| v.clamp(Vec3A::splat(-f32::MAX), Vec3A::splat(f32::MAX));
        let inv_exit = finite(inv_d * (1.0 + 4.0 * f32::EPSILON));
        let o_exit = exit_origin(o, inv_d);
        let inv_d = finite(inv_d);
        // SAFETY: the caller's. (No closure for the splats, as in `Planes::hit`.)
        unsafe {
            RayBox {
                o: [L::splat(o.x), L::splat(o.y), L::splat(o.z)],
                o_exit: [L::splat(o_exit.x), L::splat(o_exit.y), L::splat(o_exit.z)],
                inv_d: [L::splat(inv_d.x), L::splat(inv_d.y), L::splat(inv_d.z)],
                inv_exit: [
                    L::splat(inv_exit.x),
                    L::splat(inv_exit.y),
                    L::splat(inv_exit.z),
                ],
                back: {
                    let m = inv_d.is_negative_bitmask() as usize;
                    [m & 1, (m >> 1) & 1, m >> 2]
                },
            }
        }
    }
}

/// The origin `o` of a ray of reciprocal direction `inv_d` as the node test's exit sides take
/// it ([`RayBox::o_exit`]): on an axis where `inv_d` is infinite, one ulp away from the side
/// the ray leaves a slab by (up when it runs towards smaller coordinates, `-0` included).
#[inline(always)]
fn exit_origin(o: Vec3A, inv_d: Vec3A) -> Vec3A {
    let away = |o: f32, inv: f32| match (inv.is_infinite(), inv < 0.0) {
        (false, _) => o,
        (true, true) => o.next_up(),
        (true, false) => o.next_down(),
    };
    Vec3A::new(away(o.x, inv_d.x), away(o.y, inv_d.y), away(o.z, inv_d.z))
}

/// `t` raised by `1 + 4 eps`: the reach the node test compares a computed entry distance with.
/// An entry distance is computed with a relative error below that margin, so a box that the
/// ray enters before `t` in exact arithmetic is kept even where its computed entry comes out a
/// few ulps beyond `t`, as at a vertex shared by triangles whose hits differ by an ulp.
#[inline(always)]
fn grown(t: f32) -> f32 {
    t * (1.0 + 4.0 * f32::EPSILON)
}

/// The nearest entry left on a nearest-hit traversal's stack (`stack[..sp]`) that a ray of
/// reach `t_max` can still need, if any: entries a hit found meanwhile has put out of reach
/// are skipped.
///
/// # Safety
/// `stack[..*sp]` must be initialised.
#[inline(always)]
unsafe fn pop(stack: &[MaybeUninit<(u32, f32)>], sp: &mut usize, t_max: f32) -> Option<ChildRef> {
    while *sp > 0 {
        *sp -= 1;
        // SAFETY: the caller's.
        let (c, t) = unsafe { stack[*sp].assume_init() };
        if t <= grown(t_max) {
            return Some(c);
        }
    }
    None
}

/// Traversal stack size: a wide level leaves at most seven more entries on the stack than it
/// took (`closest` pushes seven of eight children and visits the eighth; `any` pops one and
/// pushes eight), and the binary tree is at most 48 + 32 levels deep (`bvh::MEDIAN_DEPTH` plus
/// log2 of a `u32` primitive count), so a wide tree at most 80. (`closest`'s array has one slot
/// more: `WideBvh::enter` writes the child it visits next in the slot above those it pushes.)
const STACK: usize = (WIDTH - 1) * 80;

/// A node as the node test reads it: its children and their boxes' sides.
trait Planes {
    /// The children.
    fn children(&self) -> &[ChildRef; WIDTH];

    /// The coordinates on `axis` of the eight children's largest sides if `side` is 1, else
    /// (0) of their smallest.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    unsafe fn planes<L: Lanes8>(&self, axis: usize, side: usize) -> L;

    /// Entry distances of the eight children and the lanes whose box the ray enters within
    /// `(0, t_max]`, `t_max` [`grown`] by the margin for rounding.
    ///
    /// The slab test of [`Aabb::hit`](crate::geometry::Aabb::hit) with each slab's entry and
    /// exit sides chosen by the sign of the direction (as Embree does) instead of a min and max
    /// of both, and the exits' margin for rounding in their reciprocal ([`RayBox::inv_exit`])
    /// rather than in a product after the minimum, so that the chain of operations from the
    /// node's load to the mask is short: the traversal of an incoherent ray waits on it at every
    /// node. No NaN arises: [`RayBox::new`] keeps the reciprocal direction finite.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn hit<L: Lanes8>(&self, r: &RayBox<L>, t_max: f32) -> (L, u32) {
        // SAFETY: the caller's. (No closure here: one would be compiled without the
        // traversal's target feature and keep the AVX2 intrinsics calls.)
        unsafe {
            let (x, y, z) = (
                self.side(r, 0, false),
                self.side(r, 1, false),
                self.side(r, 2, false),
            );
            // (Pairs, then the pairs' results: two steps of latency instead of three.)
            let near = x.max(y).max(z.max(L::splat(0.0)));
            let (x, y, z) = (
                self.side(r, 0, true),
                self.side(r, 1, true),
                self.side(r, 2, true),
            );
            let far = x.min(y).min(z.min(L::splat(grown(t_max))));
            (near, near.le(far) & L::ne_u32(self.children(), EMPTY))
        }
    }

    /// The distances along `r` to the eight children's entry sides on `axis` (exit sides if
    /// `exit`): the side facing the ray's origin is the entry one.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn side<L: Lanes8>(&self, r: &RayBox<L>, axis: usize, exit: bool) -> L {
        let (o, inv) = if exit {
            (&r.o_exit[axis], &r.inv_exit[axis])
        } else {
            (&r.o[axis], &r.inv_d[axis])
        };
        // SAFETY: the caller's.
        unsafe {
            self.planes::<L>(axis, r.back[axis] ^ exit as usize)
                .sub(*o)
                .mul(*inv)
        }
    }
}

impl Planes for WideNode {
    #[inline(always)]
    fn children(&self) -> &[ChildRef; WIDTH] {
        &self.child
    }

    /// The grid coordinates decoded as the build checked them: `origin + q * step`.
    #[inline(always)]
    unsafe fn planes<L: Lanes8>(&self, axis: usize, side: usize) -> L {
        let q = &self.sides[axis][side & 1];
        // SAFETY: the caller's.
        unsafe { L::splat(self.origin[axis]).add(L::widen(q).mul(L::splat(self.step[axis]))) }
    }
}

impl Planes for TopNode {
    #[inline(always)]
    fn children(&self) -> &[ChildRef; WIDTH] {
        &self.child
    }

    #[inline(always)]
    unsafe fn planes<L: Lanes8>(&self, axis: usize, side: usize) -> L {
        // SAFETY: the caller's.
        unsafe { L::load(&self.sides[axis][side & 1]) }
    }
}

/// The leaf test of a nearest-hit walk ([`WideBvh::closest`]): the nearest hit among leaf
/// `leaf`'s primitives within `(0, t_max]`, its primitive and distance. A closure is one (and
/// may stay a call, compiled for the baseline); a type of its own can have its test inlined
/// into the walk (`#[inline(always)]`), and so compiled for the walk's instruction set.
pub trait NearestLeaf {
    /// The nearest hit in leaf `leaf` within `(0, t_max]`.
    fn nearest(&mut self, leaf: u32, t_max: f32) -> Option<(u32, f32)>;
}

impl<F: FnMut(u32, f32) -> Option<(u32, f32)>> NearestLeaf for F {
    #[inline(always)]
    fn nearest(&mut self, leaf: u32, t_max: f32) -> Option<(u32, f32)> {
        self(leaf, t_max)
    }
}

/// The leaf test of an any-hit walk ([`WideBvh::any`]): whether a primitive of leaf `leaf`
/// blocks `ray`. As [`NearestLeaf`], a closure or a type of its own.
pub trait AnyLeaf {
    /// True if a primitive of leaf `leaf` is hit within `(0, ray.t_max]`.
    fn any(&mut self, leaf: u32, ray: &BvhRay) -> bool;
}

impl<F: FnMut(u32, &BvhRay) -> bool> AnyLeaf for F {
    #[inline(always)]
    fn any(&mut self, leaf: u32, ray: &BvhRay) -> bool {
        self(leaf, ray)
    }
}

impl WideBvh {
    /// Collapse a binary tree (nodes in the layout of [`super::Bvh`]: an interior node's first
    /// child follows it and `index` is its second) into eight-wide nodes. Each wide node takes a
    /// binary node's children and opens interior ones among them, up to eight entries, as the
    /// grouping of least expected node visits plans it (`Plan`, a dynamic programme over the
    /// whole tree).
    ///
    /// Returns the tree and its leaves, each a binary leaf's `(first, count)`: a leaf child's
    /// payload is its index there. Leaves and nodes come in depth-first order; the top levels'
    /// subtrees are collapsed in parallel and joined in that order, so the result does not
    /// depend on the thread count.
    pub fn collapse(binary: &[Node]) -> (WideBvh, Vec<(usize, usize)>) {
        if binary.is_empty() {
            return (WideBvh::default(), Vec::new());
        }
        let root = binary[0];
        if root.count > 0 {
            // A single leaf: a root with one child.
            let node = TopNode::from_children(binary, &[0], &[LEAF]);
            let leaves = vec![(root.index as usize, root.count as usize)];
            let bvh = WideBvh {
                top: vec![node],
                nodes: Vec::new(),
                isa: Isa::detect(),
            };
            return (bvh, leaves);
        }
        let part = collapse_part(binary, &Plan::new(binary), 0, 0, PARALLEL_LEVELS);
        let bvh = WideBvh {
            top: part.top,
            nodes: part.nodes,
            isa: Isa::detect(),
        };
        (bvh, part.leaves)
    }

    /// True if the tree holds nothing (no ray can hit anything in it).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.top.is_empty()
    }

    /// The root's reference (a [`TOP`] one), for walks of the tree; only a tree that is not
    /// [empty](WideBvh::is_empty) has a root.
    pub fn root(&self) -> ChildRef {
        TOP
    }

    /// Nodes of both kinds.
    pub fn node_count(&self) -> usize {
        self.top.len() + self.nodes.len()
    }

    /// Bytes of the nodes of both kinds.
    pub fn node_bytes(&self) -> usize {
        std::mem::size_of_val(&self.top[..]) + std::mem::size_of_val(&self.nodes[..])
    }

    /// The children of interior node `r` and the boxes the traversal tests for them (`None`
    /// for an unused slot), with the largest margin, per axis, that a box may leave around its
    /// contents: a quantised node's grid step, 0 for a top node's exact boxes.
    pub fn child_boxes(&self, r: ChildRef) -> ([ChildRef; WIDTH], [ChildBox; WIDTH], glam::Vec3) {
        assert!(r & LEAF == 0, "{r:#x} is a leaf");
        if r & TOP != 0 {
            let n = &self.top[(r & !TOP) as usize];
            let boxes = std::array::from_fn(|slot| n.child_box(slot));
            (n.child, boxes, glam::Vec3::ZERO)
        } else {
            let n = &self.nodes[r as usize];
            let boxes = std::array::from_fn(|slot| n.child_box(slot));
            (n.child, boxes, glam::Vec3::from_array(n.step))
        }
    }

    /// Nearest primitive hit: its index and distance. `test(leaf, t_max)` is the nearest hit
    /// of `ray` in `(0, t_max]` among the primitives of the leaf with payload `leaf`: the
    /// traversal gives the reach, shortened by each hit, and the caller keeps the ray (and what
    /// its leaf tests need of it), so no copy of the ray is made per leaf. Every hit `test`
    /// returns becomes the best so far, so the last one it returns is the answer (a caller
    /// may keep what it computed for that hit).
    ///
    /// The nearest child a node test finds is visited next; every other child it finds is
    /// asked for as soon as it is found: interior nodes here (but top
    /// nodes, which stay cached), leaves by `touch(leaf)` (which [`prefetch`]es the leaf's
    /// data, or does nothing), so that the cache misses of an incoherent ray overlap instead of
    /// following one another. Any-hit traversal ([`WideBvh::any`]) does not prefetch: it
    /// measured no faster with it.
    #[inline]
    pub fn closest(
        &self,
        ray: &BvhRay,
        test: impl FnMut(u32, f32) -> Option<(u32, f32)>,
        touch: impl Fn(u32),
    ) -> Option<(u32, f32)> {
        self.closest_tallied(ray, test, touch, &())
    }

    /// [`WideBvh::closest`], telling `tally` each node test.
    #[inline]
    pub fn closest_tallied(
        &self,
        ray: &BvhRay,
        test: impl NearestLeaf,
        touch: impl Fn(u32),
        tally: &impl Tally,
    ) -> Option<(u32, f32)> {
        debug_assert!(self.isa.available());
        match self.isa {
            // SAFETY: `isa` is private to this file and set only by `collapse` and `Default`
            // (both `Isa::detect`) and by `set_isa`, which checks: AVX2 (or AVX-512, whose
            // CPUs all have AVX2: its node test is AVX2's) only where the CPU has it.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 | Isa::Avx512 => unsafe { self.closest_avx2(ray, test, touch, tally) },
            _ => self.closest_baseline(ray, test, touch, tally),
        }
    }

    /// [`WideBvh::closest`] in two SSE halves, kept out of line as the AVX2 one is: inlined,
    /// its stack array (4.5 KB) made the caller's frame that large, a stack probe for every
    /// ray whichever instruction set runs (rays that miss measured 4-6% slower with it).
    #[inline(never)]
    fn closest_baseline(
        &self,
        ray: &BvhRay,
        test: impl NearestLeaf,
        touch: impl Fn(u32),
        tally: &impl Tally,
    ) -> Option<(u32, f32)> {
        // SAFETY: the baseline runs on every CPU.
        unsafe { self.closest_in::<Halves>(ray, test, touch, tally) }
    }

    /// True if `test(leaf, ray)` holds for some leaf whose box the ray enters within
    /// `(0, ray.t_max]` (any-hit query for shadow rays).
    #[inline]
    pub fn any(&self, ray: &BvhRay, test: impl FnMut(u32, &BvhRay) -> bool) -> bool {
        self.any_tallied(ray, test, &())
    }

    /// [`WideBvh::any`], telling `tally` each node test.
    #[inline]
    pub fn any_tallied(&self, ray: &BvhRay, test: impl AnyLeaf, tally: &impl Tally) -> bool {
        debug_assert!(self.isa.available());
        match self.isa {
            // SAFETY: `isa` is private to this file and set only by `collapse` and `Default`
            // (both `Isa::detect`) and by `set_isa`, which checks: AVX2 (or AVX-512, whose
            // CPUs all have AVX2: its node test is AVX2's) only where the CPU has it.
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 | Isa::Avx512 => unsafe { self.any_avx2(ray, test, tally) },
            // SAFETY: the baseline runs on every CPU.
            _ => unsafe { self.any_in::<Halves>(ray, test, tally) },
        }
    }

    /// The instruction set the traversals run.
    pub fn isa(&self) -> Isa {
        self.isa
    }

    /// Run the traversals in `isa` from now on, if this CPU has it; returns whether it does
    /// (the answers are the same in every instruction set, only the speed differs).
    pub fn set_isa(&mut self, isa: Isa) -> bool {
        let ok = isa.available();
        if ok {
            self.isa = isa;
        }
        ok
    }

    /// [`WideBvh::closest`] compiled for AVX2, the node test inlined into it (a leaf test that
    /// is a closure may stay a call).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn closest_avx2(
        &self,
        ray: &BvhRay,
        test: impl NearestLeaf,
        touch: impl Fn(u32),
        tally: &impl Tally,
    ) -> Option<(u32, f32)> {
        // SAFETY: the caller's.
        unsafe { self.closest_avx2_inline(ray, test, touch, tally) }
    }

    /// [`WideBvh::any`] compiled for AVX2, the node test inlined into it (a leaf test that is a
    /// closure may stay a call).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn any_avx2(&self, ray: &BvhRay, test: impl AnyLeaf, tally: &impl Tally) -> bool {
        // SAFETY: the caller's.
        unsafe { self.any_avx2_inline(ray, test, tally) }
    }

    /// [`WideBvh::closest_tallied`] with AVX2's node test, inlined into its caller, which
    /// should be compiled for AVX2 (so the walk and an inlined leaf test run in it).
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub unsafe fn closest_avx2_inline(
        &self,
        ray: &BvhRay,
        test: impl NearestLeaf,
        touch: impl Fn(u32),
        tally: &impl Tally,
    ) -> Option<(u32, f32)> {
        // SAFETY: the caller's.
        unsafe { self.closest_in::<super::simd::avx2::Avx2>(ray, test, touch, tally) }
    }

    /// [`WideBvh::any_tallied`] with AVX2's node test, inlined into its caller, which should
    /// be compiled for AVX2.
    ///
    /// # Safety
    /// The CPU must have AVX2.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub unsafe fn any_avx2_inline(
        &self,
        ray: &BvhRay,
        test: impl AnyLeaf,
        tally: &impl Tally,
    ) -> bool {
        // SAFETY: the caller's.
        unsafe { self.any_in::<super::simd::avx2::Avx2>(ray, test, tally) }
    }

    /// The node test of interior node `node` (a reference): the children's entry distances,
    /// the lanes whose box the ray enters within `(0, t_max]`, and the children.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn visit<L: Lanes8>(
        &self,
        node: ChildRef,
        rb: &RayBox<L>,
        t_max: f32,
    ) -> (L, u32, &[ChildRef; WIDTH]) {
        // SAFETY: the caller's.
        unsafe {
            if node & TOP != 0 {
                let n = &self.top[(node & !TOP) as usize];
                let (near, mask) = n.hit(rb, t_max);
                (near, mask, &n.child)
            } else {
                let n = &self.nodes[node as usize];
                let (near, mask) = n.hit(rb, t_max);
                (near, mask, &n.child)
            }
        }
    }

    /// [`WideBvh::closest`] with the node test in lanes `L`.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn closest_in<L: Lanes8>(
        &self,
        ray: &BvhRay,
        mut test: impl NearestLeaf,
        touch: impl Fn(u32),
        tally: &impl Tally,
    ) -> Option<(u32, f32)> {
        if self.is_empty() {
            return None;
        }
        // SAFETY: the caller's.
        let rb = unsafe { RayBox::<L>::new(ray.o, ray.inv_d) };
        // The root first: most rays that miss the scene enter none of its children (85% of
        // the misses of `rtis bench`'s incoherent rays at 10k triangles), and they leave
        // before the traversal's state is set up (5-11% less time per miss, measured).
        let root = &self.top[0];
        tally.nodes(1);
        // SAFETY: the caller's.
        let (mut near, mut mask) = unsafe { root.hit(&rb, ray.t_max) };
        if mask == 0 {
            return None;
        }
        let mut child = &root.child;
        // The ray's reach, shortened by each hit. (Not a copy of the whole ray: the caller has
        // just written it, field by field, and a wide read of those fresh stores waits for
        // them; it measured 7% of the traversal's time at 10k triangles.)
        let mut t_max = ray.t_max;
        let mut best = None;
        // (One slot more than the stack can hold: `enter` writes the child it visits next at
        // the slot above the ones it pushes.)
        let mut stack = [MaybeUninit::<(u32, f32)>::uninit(); STACK + 1];
        let mut sp = 0usize;
        loop {
            // The node test's outcome (`near`, `mask`, `child`) gives the child visited next:
            // the nearest child entered, the farther ones waiting on the stack; or, if none,
            // the nearest entry on the stack.
            let next = if mask != 0 {
                // SAFETY: the caller's.
                Some(unsafe { self.enter(near, mask, child, &mut stack, &mut sp, &touch) })
            } else {
                // SAFETY: entries below `sp` were written before `sp` was raised past them.
                unsafe { pop(&stack, &mut sp, t_max) }
            };
            let Some(mut cur) = next else {
                return best;
            };
            // One place tests leaves: a hit shortens the reach and becomes the best so far.
            while cur & LEAF != 0 {
                if let Some((p, t)) = test.nearest(cur & !LEAF, t_max) {
                    t_max = t;
                    best = Some((p, t));
                }
                // SAFETY: as above.
                let Some(c) = (unsafe { pop(&stack, &mut sp, t_max) }) else {
                    return best;
                };
                cur = c;
            }
            tally.nodes(1);
            // SAFETY: the caller's.
            (near, mask, child) = unsafe { self.visit(cur, &rb, t_max) };
        }
    }

    /// The child to visit after a node test that found the children `mask` (not empty) at
    /// entry distances `near`: the nearest; the others are pushed on the stack, farthest
    /// first, and asked for ([`WideBvh::ask`]) so that their cache misses overlap. Of equal
    /// distances, the later slot is visited first.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set. `mask` must not be empty and its lanes of
    /// `near` must not be NaN (the node test's distances never are): the places counted for
    /// the children are then `0..k`, so every slot from `*sp` to the new `*sp` is written.
    #[inline(always)]
    unsafe fn enter<L: Lanes8>(
        &self,
        near: L,
        mask: u32,
        child: &[ChildRef; WIDTH],
        stack: &mut [MaybeUninit<(u32, f32)>; STACK + 1],
        sp: &mut usize,
        touch: &impl Fn(u32),
    ) -> ChildRef {
        let first = mask.trailing_zeros() as usize;
        let rest = mask & (mask - 1);
        // One child entered (the common case for coherent rays): no ordering to do.
        if rest == 0 {
            return child[first];
        }
        // SAFETY: the caller's.
        let dist = unsafe { near.to_array() };
        // Two (the common case of several): the farther waits. (The placement below measured
        // 0.5-1.2% slower on hit rays for two.)
        if rest & (rest - 1) == 0 {
            let second = rest.trailing_zeros() as usize;
            let (a, b) = ((child[first], dist[first]), (child[second], dist[second]));
            let (go, wait) = if a.1 < b.1 { (a, b) } else { (b, a) };
            self.ask(wait.0, touch);
            stack[*sp].write(wait);
            *sp += 1;
            return go.0;
        }
        // More: each child's place among them, farthest first, counted from two comparisons
        // of its distance with all eight lanes, so that no branch depends on the distances
        // (the insertion sort it replaced measured 1-4% slower on hit rays). Each is written
        // at its place above the stack; the nearest, last, is visited now and the stack keeps
        // the others.
        let k = mask.count_ones() as usize;
        let mut go = EMPTY;
        let mut m = mask;
        while m != 0 {
            let i = m.trailing_zeros() as usize;
            m &= m - 1;
            // SAFETY: the caller's.
            let (nearer_or_level, farther_or_level) = unsafe {
                let d = L::splat(dist[i]);
                (near.le(d), d.le(near))
            };
            // Before child `i`: the farther children, and those as far in an earlier slot.
            let earlier = (1 << i) - 1;
            let place = mask & (!nearer_or_level | (farther_or_level & earlier));
            let place = place.count_ones() as usize;
            self.ask(child[i], touch);
            stack[*sp + place].write((child[i], dist[i]));
            go = if place == k - 1 { child[i] } else { go };
        }
        *sp += k - 1;
        go
    }

    /// Ask for child `c`'s data ahead of its visit: a leaf's through `touch`, an interior
    /// node's by [`prefetch`], except a top node's (they are few, and every ray reads them, so
    /// they stay cached).
    #[inline(always)]
    fn ask(&self, c: ChildRef, touch: &impl Fn(u32)) {
        if c & LEAF != 0 {
            touch(c & !LEAF);
        } else if c & TOP == 0 {
            prefetch(self.nodes.as_ptr().wrapping_add(c as usize));
        }
    }

    /// [`WideBvh::any`] with the node test in lanes `L`.
    ///
    /// # Safety
    /// The CPU must run `L`'s instruction set.
    #[inline(always)]
    unsafe fn any_in<L: Lanes8>(
        &self,
        ray: &BvhRay,
        mut test: impl AnyLeaf,
        tally: &impl Tally,
    ) -> bool {
        if self.is_empty() {
            return false;
        }
        // SAFETY: the caller's.
        let rb = unsafe { RayBox::<L>::new(ray.o, ray.inv_d) };
        let mut stack = [MaybeUninit::<u32>::uninit(); STACK];
        let mut sp = 0usize;
        let mut node = self.root();
        loop {
            tally.nodes(1);
            // SAFETY: the caller's.
            let (_, mut mask, child) = unsafe { self.visit(node, &rb, ray.t_max) };
            while mask != 0 {
                let i = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                let c = child[i];
                if c & LEAF != 0 {
                    if test.any(c & !LEAF, ray) {
                        return true;
                    }
                } else {
                    stack[sp].write(c);
                    sp += 1;
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            // SAFETY: entries below `sp` were written before `sp` was raised past them.
            node = unsafe { stack[sp].assume_init() };
        }
    }
}

impl WideNode {
    /// The node over binary nodes `kids` with references `refs`.
    fn from_children(binary: &[Node], kids: &[usize], refs: &[ChildRef]) -> WideNode {
        let (mut lo_all, mut hi_all) = (glam::Vec3::INFINITY, glam::Vec3::NEG_INFINITY);
        for &k in kids {
            lo_all = lo_all.min(binary[k].min);
            hi_all = hi_all.max(binary[k].max);
        }
        let mut node = WideNode {
            origin: [0.0; 3],
            step: [0.0; 3],
            sides: [[[0; WIDTH]; 2]; 3],
            child: [EMPTY; WIDTH],
        };
        if kids.is_empty() {
            return node;
        }
        for axis in 0..3 {
            node.origin[axis] = lo_all[axis];
            node.step[axis] = grid_step(lo_all[axis], hi_all[axis]);
        }
        let n = kids.len();
        for axis in 0..3 {
            let (mut lo, mut hi) = ([0.0f32; WIDTH], [0.0f32; WIDTH]);
            for (k, &kid) in kids.iter().enumerate() {
                // Through arrays: glam's `Vec3` index is a `match`.
                let (min, max): (&[f32; 3], &[f32; 3]) =
                    (binary[kid].min.as_ref(), binary[kid].max.as_ref());
                (lo[k], hi[k]) = (min[axis], max[axis]);
            }
            let grid = (node.origin[axis], node.step[axis], 1.0 / node.step[axis]);
            node.sides[axis] = <[[u8; WIDTH]; 2]>::from(quantize_all(&lo, &hi, n, grid));
        }
        node.child[..n].copy_from_slice(refs);
        node
    }

    /// The decoded box of child `slot` (what the traversal tests), or `None` if unused.
    pub fn child_box(&self, slot: usize) -> ChildBox {
        (self.child[slot] != EMPTY).then(|| {
            let decode = |side: usize| {
                glam::Vec3::from_array(
                    [0, 1, 2]
                        .map(|a| self.origin[a] + self.sides[a][side][slot] as f32 * self.step[a]),
                )
            };
            (decode(0), decode(1))
        })
    }
}

impl TopNode {
    /// The box of child `slot` (exact: what the traversal tests), or `None` if unused.
    pub fn child_box(&self, slot: usize) -> ChildBox {
        let corner =
            |side: usize| glam::Vec3::from_array([0, 1, 2].map(|a| self.sides[a][side][slot]));
        (self.child[slot] != EMPTY).then(|| (corner(0), corner(1)))
    }

    /// The node over binary nodes `kids` with references `refs`: their exact boxes.
    fn from_children(binary: &[Node], kids: &[usize], refs: &[ChildRef]) -> TopNode {
        // Unused slots: an empty box (their lanes are masked out by `EMPTY` as well).
        let mut node = TopNode {
            sides: [[[f32::INFINITY; WIDTH], [f32::NEG_INFINITY; WIDTH]]; 3],
            child: [EMPTY; WIDTH],
        };
        for (slot, &kid) in kids.iter().enumerate() {
            let (min, max): (&[f32; 3], &[f32; 3]) =
                (binary[kid].min.as_ref(), binary[kid].max.as_ref());
            for axis in 0..3 {
                node.sides[axis][0][slot] = min[axis];
                node.sides[axis][1][slot] = max[axis];
            }
        }
        node.child[..refs.len()].copy_from_slice(refs);
        node
    }
}

/// Wide levels whose subtrees are collapsed in parallel (up to 8^2 = 64 tasks).
const PARALLEL_LEVELS: u32 = 2;

/// A collapsed subtree, its root first (in `top` if it lies in the top levels, else in
/// `nodes`), with node indices and leaf payloads counted from 0.
struct Part {
    top: Vec<TopNode>,
    nodes: Vec<WideNode>,
    leaves: Vec<(usize, usize)>,
}

impl Part {
    /// A part with nothing in it yet.
    fn new() -> Part {
        Part {
            top: Vec::new(),
            nodes: Vec::new(),
            leaves: Vec::new(),
        }
    }

    /// A reference to the next leaf, `(first, count)`, which it appends.
    fn leaf(&mut self, range: (usize, usize)) -> ChildRef {
        self.leaves.push(range);
        let payload = (self.leaves.len() - 1) as u32;
        // Below `LEAF - 1`, so that no leaf reference equals `EMPTY`.
        assert!(payload < LEAF - 1, "at most 2^31 - 1 leaves");
        LEAF | payload
    }

    /// A reference to a new node of the kind that depth `depth` takes, its contents to be set
    /// by [`Part::set`] once its children are known.
    fn reserve(&mut self, depth: u32) -> ChildRef {
        let (index, kind) = if depth < TOP_LEVELS {
            self.top.push(TopNode::from_children(&[], &[], &[]));
            (self.top.len() - 1, TOP)
        } else {
            self.nodes.push(WideNode::from_children(&[], &[], &[]));
            (self.nodes.len() - 1, 0)
        };
        // Below `TOP`, so that no node reference has `TOP` or `LEAF` set by its index.
        assert!(index < TOP as usize, "at most 2^30 nodes of each kind");
        kind | index as u32
    }

    /// Set node `r`, reserved by [`Part::reserve`], to the node over binary nodes `kids`
    /// with references `refs`.
    fn set(&mut self, r: ChildRef, binary: &[Node], kids: &[usize], refs: &[ChildRef]) {
        if r & TOP != 0 {
            self.top[(r & !TOP) as usize] = TopNode::from_children(binary, kids, refs);
        } else {
            self.nodes[r as usize] = WideNode::from_children(binary, kids, refs);
        }
    }

    /// Append `sub`, with its references shifted by what precedes it; returns the reference
    /// of its root (a top node if it has any: a part below the top levels has none).
    fn append(&mut self, sub: Part) -> ChildRef {
        let top_root = !sub.top.is_empty();
        // Within the bounds `reserve` and `leaf` check for one part, now for the join.
        assert!(
            self.top.len() + sub.top.len() < TOP as usize
                && self.nodes.len() + sub.nodes.len() < TOP as usize
                && self.leaves.len() + sub.leaves.len() < (LEAF - 1) as usize,
            "at most 2^30 nodes of each kind and 2^31 - 1 leaves"
        );
        let at = [self.leaves.len(), self.top.len(), self.nodes.len()].map(|n| n as u32);
        let shift = |child: &mut [ChildRef; WIDTH]| {
            for c in child.iter_mut().filter(|c| **c != EMPTY) {
                *c += match (*c & LEAF != 0, *c & TOP != 0) {
                    (true, _) => at[0],
                    (false, true) => at[1],
                    (false, false) => at[2],
                };
            }
        };
        self.top.extend(sub.top.into_iter().map(|mut n| {
            shift(&mut n.child);
            n
        }));
        self.nodes.extend(sub.nodes.into_iter().map(|mut n| {
            shift(&mut n.child);
            n
        }));
        self.leaves.extend(sub.leaves);
        if top_root { TOP | at[1] } else { at[2] }
    }
}

/// How the collapse groups the binary tree into wide nodes, chosen for the least expected
/// number of wide nodes that a random line through the root's box enters: the sum of the wide
/// nodes' box surfaces over the root's (the SAH's node term; the leaves' term is the same for
/// every grouping, as the binary leaves are kept). A simplified form of the dynamic programme
/// of Ylitie et al. (2017), which also chooses the leaves.
///
/// For each binary node `n` and each `j` in `1..=8`, the least cost of covering `n`'s subtree
/// with at most `j` entries of a parent's slots (leaves, or wide nodes with their subtrees):
/// for a leaf, 0; for an interior node, either one entry, `n` made a wide node, at its relative
/// surface plus the least cost of covering its two children with eight slots shared between
/// them, or (for `j > 1`) its children covering `j` slots shared between them. Filled from the
/// leaves up: a child's index is above its parent's in the binary layout. Over the displaced
/// spheres of `rtis bench` (10k to 1M triangles), it makes 17-21% fewer wide nodes than the
/// greedy collapse it replaced (which opened the largest children first), 1.4-1.8 fewer bytes
/// per triangle, and 2.0-3.3% fewer expected visits; rays measured as fast as before (within
/// 1%). The table is filled by subtrees in parallel ([`PLAN_PARALLEL_MIN`]).
///
/// Entry `n` holds, for `j` in `2..=8`, four bits at `4 * (j - 2)`: the slots of the first
/// child's share (`1..=7`, the second child taking the rest) in the low three, and in the
/// fourth whether `n` is kept as one entry (a wide node). Of equal costs, `n` is opened (one
/// wide node fewer) and the smaller first share is kept.
struct Plan(Vec<u32>);

/// Subtrees of more binary nodes than this fill their plan in parallel.
const PLAN_PARALLEL_MIN: usize = 4096;

/// A node's box surface (halved), in doubles.
fn surface(n: &Node) -> f64 {
    let d = n.max.as_dvec3() - n.min.as_dvec3();
    d.x * d.y + d.y * d.z + d.z * d.x
}

/// The plan's table over the subtree of binary node `first`, which the depth-first layout
/// keeps in `binary[first..first + cost.len()]`.
struct Subtree<'a> {
    binary: &'a [Node],
    first: usize,
    cost: &'a mut [[f32; WIDTH]],
    choice: &'a mut [u32],
}

impl Subtree<'_> {
    /// Fill the table, from the leaves up; the two subtrees below a node of more than
    /// `parallel_min` nodes in parallel. `scale` is one over the root's surface.
    fn fill(&mut self, scale: f64, parallel_min: usize) {
        let node = &self.binary[self.first];
        if node.count == 0 && self.cost.len() > parallel_min {
            // This node, then its first subtree, then its second, in the table's order.
            let second = node.index as usize - self.first;
            let (me, rest) = self.cost.split_at_mut(1);
            let (cost_l, cost_r) = rest.split_at_mut(second - 1);
            let (my_choice, rest) = self.choice.split_at_mut(1);
            let (choice_l, choice_r) = rest.split_at_mut(second - 1);
            let (binary, first) = (self.binary, self.first);
            let mut l = Subtree {
                binary,
                first: first + 1,
                cost: cost_l,
                choice: choice_l,
            };
            let mut r = Subtree {
                binary,
                first: first + second,
                cost: cost_r,
                choice: choice_r,
            };
            rayon::join(
                || l.fill(scale, parallel_min),
                || r.fill(scale, parallel_min),
            );
            (me[0], my_choice[0]) = entry(node, &l.cost[0], &r.cost[0], scale);
            return;
        }
        for k in (0..self.cost.len()).rev() {
            let node = &self.binary[self.first + k];
            if node.count == 0 {
                let second = node.index as usize - self.first;
                let (l, r) = (&self.cost[k + 1], &self.cost[second]);
                (self.cost[k], self.choice[k]) = entry(node, l, r, scale);
            }
        }
    }
}

/// Interior node `node`'s costs and choices (see [`Plan`]) from its children's costs `l` and
/// `r`; `scale` is one over the root's surface.
fn entry(node: &Node, l: &[f32; WIDTH], r: &[f32; WIDTH], scale: f64) -> ([f32; WIDTH], u32) {
    // `shared[j - 2]`: the least cost of the children in `j` slots shared (2 to 8), and the
    // first's share.
    let shared: [(f32, usize); WIDTH - 1] = std::array::from_fn(|i| {
        let j = i + 2;
        (2..j).fold((l[0] + r[j - 2], 1), |best, k| {
            let c = l[k - 1] + r[j - k - 1];
            if c < best.0 { (c, k) } else { best }
        })
    });
    let whole = (surface(node) * scale) as f32 + shared[WIDTH - 2].0;
    let mut row = [whole; WIDTH];
    let mut bits = 0;
    for j in 2..=WIDTH {
        let (c, k) = shared[j - 2];
        let keep = whole < c;
        row[j - 1] = if keep { whole } else { c };
        bits |= (k as u32 | (keep as u32) << 3) << (4 * (j - 2));
    }
    (row, bits)
}

impl Plan {
    /// The grouping of `binary` (not empty).
    fn new(binary: &[Node]) -> Plan {
        Plan::filled(binary, PLAN_PARALLEL_MIN)
    }

    /// [`Plan::new`], its subtrees of more than `parallel_min` nodes filled in parallel, each
    /// from its leaves up: a node's entry depends on its children's alone, so the plan is the
    /// same whatever the split.
    fn filled(binary: &[Node], parallel_min: usize) -> Plan {
        // Surfaces in doubles, relative to the root's: each at most 1 (a child's box lies in
        // its parent's), so no sum of them overflows, whatever the scene's extent.
        let root = surface(&binary[0]);
        let scale = if root > 0.0 { 1.0 / root } else { 1.0 };
        // `cost[n][j - 1]`: the least cost of `n`'s subtree in at most `j` slots.
        let mut cost = vec![[0.0f32; WIDTH]; binary.len()];
        let mut choice = vec![0u32; binary.len()];
        let mut sub = Subtree {
            binary,
            first: 0,
            cost: &mut cost,
            choice: &mut choice,
        };
        sub.fill(scale, parallel_min);
        Plan(choice)
    }

    /// Interior node `n`'s choice for `j` slots (`2..=8`): the first child's share, and
    /// whether `n` stays one entry.
    fn choice(&self, n: usize, j: usize) -> (usize, bool) {
        let bits = self.0[n] >> (4 * (j - 2));
        ((bits & 7) as usize, bits & 8 != 0)
    }

    /// Push the entries that cover binary node `n`'s subtree in at most `j` slots onto `kids`
    /// (from `*len` on), in tree order.
    fn cover(
        &self,
        binary: &[Node],
        n: usize,
        j: usize,
        kids: &mut [usize; WIDTH],
        len: &mut usize,
    ) {
        let node = &binary[n];
        let (k, keep) = if node.count > 0 || j == 1 {
            (0, true)
        } else {
            self.choice(n, j)
        };
        if keep {
            kids[*len] = n;
            *len += 1;
            return;
        }
        self.cover(binary, n + 1, k, kids, len);
        self.cover(binary, node.index as usize, j - k, kids, len);
    }

    /// The children of the wide node over binary interior node `i`, in tree order, and their
    /// number (2 to 8): `i`'s two children's entries, sharing the eight slots as planned.
    fn children(&self, binary: &[Node], i: usize) -> ([usize; WIDTH], usize) {
        let (mut kids, mut n) = ([0; WIDTH], 0);
        let k = self.choice(i, WIDTH).0;
        self.cover(binary, i + 1, k, &mut kids, &mut n);
        self.cover(
            binary,
            binary[i].index as usize,
            WIDTH - k,
            &mut kids,
            &mut n,
        );
        (kids, n)
    }
}

/// The subtree under binary interior node `i`, at wide depth `depth`, its interior children's
/// subtrees collapsed in parallel for `levels` more levels, then joined in order (each child's
/// indices shifted by what precedes it), which is what the sequential [`collapse_node`] would
/// have written.
fn collapse_part(binary: &[Node], plan: &Plan, i: usize, depth: u32, levels: u32) -> Part {
    let mut part = Part::new();
    if levels == 0 {
        collapse_node(binary, plan, i, depth, &mut part);
        return part;
    }
    let (kids, n) = plan.children(binary, i);
    let subs: Vec<Option<Part>> = kids[..n]
        .par_iter()
        .map(|&k| {
            (binary[k].count == 0).then(|| collapse_part(binary, plan, k, depth + 1, levels - 1))
        })
        .collect();
    let me = part.reserve(depth);
    let mut refs = [EMPTY; WIDTH];
    for ((r, &k), sub) in refs.iter_mut().zip(&kids[..n]).zip(subs) {
        *r = match sub {
            None => part.leaf((binary[k].index as usize, binary[k].count as usize)),
            Some(sub) => part.append(sub),
        };
    }
    part.set(me, binary, &kids[..n], &refs[..n]);
    part
}

/// Append the wide node for binary interior node `i`, at wide depth `depth`, to `part` (and,
/// after it, its subtrees, and its leaves); returns its reference.
fn collapse_node(binary: &[Node], plan: &Plan, i: usize, depth: u32, part: &mut Part) -> ChildRef {
    let (kids, n) = plan.children(binary, i);
    let me = part.reserve(depth);
    let mut refs = [EMPTY; WIDTH];
    for (r, &k) in refs.iter_mut().zip(&kids[..n]) {
        let node = binary[k];
        *r = if node.count > 0 {
            part.leaf((node.index as usize, node.count as usize))
        } else {
            collapse_node(binary, plan, k, depth + 1, part)
        };
    }
    part.set(me, binary, &kids[..n], &refs[..n]);
    me
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{Bvh, Prim};
    use crate::mesh::displaced_sphere;

    /// Joining the subtrees collapsed in parallel gives what the sequential collapse writes,
    /// node for node and leaf for leaf.
    #[test]
    fn parallel_collapse_equals_the_sequential_one() {
        let mesh = displaced_sphere(20_000, glam::Vec3::ZERO, 1.0, 0.05);
        let (bvh, _) = Bvh::build(Prim::flat_triangles(&mesh));
        let show = |p: &Part| (format!("{:?} {:?}", p.top, p.nodes), p.leaves.clone());
        let plan = Plan::new(&bvh.nodes);
        // The plan filled in parallel (over 11,000 binary nodes) is the one filled in order.
        assert!(bvh.nodes.len() > 2 * PLAN_PARALLEL_MIN);
        assert!(plan.0 == Plan::filled(&bvh.nodes, usize::MAX).0);
        let whole = collapse_part(&bvh.nodes, &plan, 0, 0, 0);
        let sequential = show(&whole);
        // Fewer, as many and more parallel levels than top levels.
        for levels in [1, 2, 3, 4, 5] {
            assert!(
                show(&collapse_part(&bvh.nodes, &plan, 0, 0, levels)) == sequential,
                "{levels} levels"
            );
        }
        assert!(sequential.1.len() > 1_000);
        assert_eq!(
            whole.top.len(),
            73,
            "three full top levels over 20k triangles"
        );
    }

    /// A binary tree in the layout of [`super::Bvh`] over `leaves` leaves, split at random,
    /// with random leaf boxes (scaled by `scale`) and each interior node's box their union.
    fn random_tree(s: &mut crate::sampling::Sampler, leaves: usize, scale: f32) -> Vec<Node> {
        fn grow(out: &mut Vec<Node>, s: &mut crate::sampling::Sampler, leaves: usize, scale: f32) {
            let me = out.len();
            let mut v = || glam::Vec3::new(s.next_f32(), s.next_f32(), s.next_f32());
            if leaves == 1 {
                let (c, r) = (v() * 10.0, v() + glam::Vec3::splat(0.01));
                let (min, max) = ((c - r) * scale, (c + r) * scale);
                let index = out.iter().filter(|n| n.count > 0).count() as u32;
                out.push(Node {
                    min,
                    index,
                    max,
                    count: 1,
                });
                return;
            }
            // (Its box and second child are set below, once its subtrees are laid out.)
            out.push(Node {
                min: glam::Vec3::ZERO,
                index: 0,
                max: glam::Vec3::ZERO,
                count: 0,
            });
            let k = (1 + (s.next_f32() * (leaves - 1) as f32) as usize).min(leaves - 1);
            grow(out, s, k, scale);
            let second = out.len();
            grow(out, s, leaves - k, scale);
            let (a, b) = (out[me + 1], out[second]);
            out[me] = Node {
                min: a.min.min(b.min),
                index: second as u32,
                max: a.max.max(b.max),
                count: 0,
            };
        }
        let mut out = Vec::new();
        grow(&mut out, s, leaves, scale);
        out
    }

    /// The planned grouping is the one of least cost (the sum of the wide nodes' surfaces)
    /// among all groupings of the binary tree into nodes of at most eight entries, found by
    /// trying every one: each non-root interior node of 200 random trees of 9 to 15 leaves
    /// either is a wide node or is opened into its parent's. The planned tree covers every
    /// leaf once, in order, with nodes of two to eight entries; so it does where the boxes'
    /// surfaces overflow a float (trees scaled by 1e19).
    #[test]
    fn the_planned_grouping_costs_least_of_all() {
        /// How many entries node `n`'s subtree takes in a wide node, given the wide ones.
        fn entries(b: &[Node], n: usize, wide: &dyn Fn(usize) -> bool) -> usize {
            if b[n].count > 0 || wide(n) {
                1
            } else {
                entries(b, n + 1, wide) + entries(b, b[n].index as usize, wide)
            }
        }
        /// The planned tree's cost (each wide node's surface, from node `i` down), with its
        /// leaves appended in the order the wide nodes hold them.
        fn planned(b: &[Node], plan: &Plan, i: usize, leaves: &mut Vec<u32>) -> f64 {
            let (kids, n) = plan.children(b, i);
            assert!((2..=WIDTH).contains(&n), "{n} children");
            let mut cost = surface(&b[i]);
            for &k in &kids[..n] {
                if b[k].count > 0 {
                    leaves.push(b[k].index);
                } else {
                    cost += planned(b, plan, k, leaves);
                }
            }
            cost
        }
        let mut s = crate::sampling::Sampler::new(7, 0, 0);
        for tree in 0..200 {
            let leaves = 9 + tree % 7;
            let scale = if tree % 10 == 9 { 1e19 } else { 1.0 };
            let b = random_tree(&mut s, leaves, scale);
            let inner: Vec<usize> = (1..b.len()).filter(|&n| b[n].count == 0).collect();
            let mut least = f64::INFINITY;
            for set in 0u32..1 << inner.len() {
                let wide = |n: usize| {
                    n == 0
                        || inner
                            .iter()
                            .position(|&m| m == n)
                            .is_some_and(|k| set >> k & 1 != 0)
                };
                let nodes = || (0..b.len()).filter(|&n| b[n].count == 0 && wide(n));
                let fits = nodes().all(|n| {
                    entries(&b, n + 1, &wide) + entries(&b, b[n].index as usize, &wide) <= WIDTH
                });
                if fits {
                    least = least.min(nodes().map(|n| surface(&b[n])).sum());
                }
            }
            let mut seen = Vec::new();
            let got = planned(&b, &Plan::new(&b), 0, &mut seen);
            assert!(
                (got - least).abs() <= least * 1e-5,
                "tree {tree}: planned {got}, least {least}"
            );
            assert_eq!(seen, (0..leaves as u32).collect::<Vec<_>>(), "tree {tree}");
            if scale > 1.0 {
                assert!(
                    (surface(&b[0]) as f32).is_infinite(),
                    "the root's surface overflows"
                );
            }
        }
    }

    /// `enter` visits the nearest child entered and leaves the others on the stack farthest
    /// first, the later slot of equal distances nearer the top: a stable sort by distance,
    /// farthest first, with the earlier slot first among equals. Every non-empty mask of the
    /// eight slots, with distances drawn from three values (so that most sets tie), in both
    /// lane types.
    #[test]
    fn children_are_entered_nearest_first_the_later_slot_of_equals_first() {
        fn check<L: Lanes8>() {
            let bvh = WideBvh::default();
            let child: [ChildRef; WIDTH] = std::array::from_fn(|i| 100 + i as u32);
            let mut s = crate::sampling::Sampler::new(3, 0, 0);
            for mask in 1u32..256 {
                for _ in 0..20 {
                    let dist: [f32; WIDTH] =
                        std::array::from_fn(|_| [0.5, 1.0, 2.0][(s.next_f32() * 3.0) as usize % 3]);
                    let mut order: Vec<usize> =
                        (0..WIDTH).filter(|i| mask & (1 << i) != 0).collect();
                    order.sort_by(|&a, &b| dist[b].total_cmp(&dist[a]));
                    let mut stack = [MaybeUninit::<(u32, f32)>::uninit(); STACK + 1];
                    // Entries below the ones pushed stay as they were.
                    stack[0].write((7, 9.0));
                    let mut sp = 1;
                    // SAFETY: the lanes' instruction set is checked by the caller.
                    let go = unsafe {
                        bvh.enter(L::load(&dist), mask, &child, &mut stack, &mut sp, &|_| {})
                    };
                    let last = *order.last().unwrap();
                    assert_eq!(go, child[last], "mask {mask:#b} {dist:?}");
                    assert_eq!(sp, order.len(), "mask {mask:#b}");
                    // SAFETY: `enter` wrote the entries below `sp`.
                    let pushed: Vec<(u32, f32)> =
                        (0..sp).map(|k| unsafe { stack[k].assume_init() }).collect();
                    let expect: Vec<(u32, f32)> = std::iter::once((7, 9.0))
                        .chain(
                            order[..order.len() - 1]
                                .iter()
                                .map(|&i| (child[i], dist[i])),
                        )
                        .collect();
                    assert_eq!(pushed, expect, "mask {mask:#b} {dist:?}");
                }
            }
        }
        check::<Halves>();
        #[cfg(target_arch = "x86_64")]
        if Isa::Avx2.available() {
            check::<crate::accel::simd::avx2::Avx2>();
        }
    }

    /// Quantisation gives the tightest grid coordinates that contain the interval, on grids
    /// at every scale and offset, for intervals anywhere on them and on grid lines (where the
    /// reciprocal's estimate is a step off most often).
    #[test]
    fn quantisation_is_the_tightest_that_contains() {
        let mut s = crate::sampling::Sampler::new(7, 0, 0);
        for case in 0..200_000 {
            let scale = 10f32.powi((case % 13) as i32 - 6);
            let origin = (s.next_f32() - 0.5) * scale * [0.0, 1.0, 1e3, 1e5][case % 4];
            let step = grid_step(origin, origin + scale * (0.5 + s.next_f32()));
            let decode = |q: u8| origin + q as f32 * step;
            let (mut lo, mut hi) = (s.next_f32() * 255.0, s.next_f32() * 255.0);
            if lo > hi {
                (lo, hi) = (hi, lo);
            }
            if case % 3 == 0 {
                (lo, hi) = (lo.floor(), hi.ceil());
            }
            let (lo, hi) = (decode(lo as u8).max(origin + lo * step), origin + hi * step);
            let hi = hi.min(decode(255)).max(lo);
            let (ql, qh) = quantize(lo, hi, origin, step, 1.0 / step);
            assert!(
                decode(ql) <= lo && decode(qh) >= hi,
                "{lo} {hi} on {origin} + q {step}"
            );
            assert!(
                ql == 255 || decode(ql + 1) > lo,
                "{lo}: {ql} not the largest"
            );
            assert!(
                qh == 0 || decode(qh - 1) < hi,
                "{hi}: {qh} not the smallest"
            );
        }
    }

    /// The eight-lane quantisation gives each of the first `n` intervals what `quantize`
    /// gives it alone, and 0 in the other slots: on grids of every scale and offset, intervals
    /// on grid lines and between them, a step of 0, a step whose reciprocal overflows, and
    /// (below) intervals at the grid's two ends, signed zeros, and grids spanning all floats.
    /// (Boxes outside their grid, or NaN, never reach it: a node's grid spans its children.)
    #[test]
    fn quantising_eight_at_once_equals_one_by_one() {
        let agree = |lo: [f32; WIDTH], hi: [f32; WIDTH], origin: f32, step: f32| {
            let (ql, qh) = quantize_all(&lo, &hi, WIDTH, (origin, step, 1.0 / step));
            for k in 0..WIDTH {
                let expect = quantize(lo[k], hi[k], origin, step, 1.0 / step);
                assert_eq!((ql[k], qh[k]), expect, "{origin} + q {step}: {lo:?} {hi:?}");
            }
        };
        for (origin, top) in [
            (0.0f32, 1.0f32),
            (-0.0, 3.0),
            (-f32::MAX, f32::MAX),
            (-1e30, 1e38),
        ] {
            let step = grid_step(origin, top);
            let end = origin + 255.0 * step;
            let mid = origin + 100.0 * step;
            let lo = [
                origin,
                origin,
                -0.0f32.max(origin),
                0.0f32.max(origin),
                mid,
                mid,
                origin,
                end,
            ];
            let hi = [
                origin,
                end,
                0.0f32.max(origin),
                end,
                mid,
                end,
                mid.next_up(),
                end,
            ];
            agree(lo, hi.map(|h| h.min(end)), origin, step);
        }
        let mut s = crate::sampling::Sampler::new(8, 0, 0);
        for case in 0..50_000 {
            let scale = 10f32.powi((case % 13) as i32 - 6);
            let origin = (s.next_f32() - 0.5) * scale * [0.0, 1.0, 1e3, 1e5][case % 4];
            let step = match case % 97 {
                0 => 0.0,
                1 => f32::from_bits(1),
                _ => grid_step(origin, origin + scale * (0.5 + s.next_f32())),
            };
            let (mut lo, mut hi) = ([0.0f32; WIDTH], [0.0f32; WIDTH]);
            for k in 0..WIDTH {
                let (mut a, mut b) = (s.next_f32() * 255.0, s.next_f32() * 255.0);
                if a > b {
                    (a, b) = (b, a);
                }
                if case % 3 == 0 {
                    (a, b) = (a.floor(), b.ceil());
                }
                (lo[k], hi[k]) = (
                    origin + a * step,
                    (origin + b * step).max(origin + a * step),
                );
            }
            let n = 1 + case % WIDTH;
            let (ql, qh) = quantize_all(&lo, &hi, n, (origin, step, 1.0 / step));
            for k in 0..WIDTH {
                let expect = if k < n {
                    quantize(lo[k], hi[k], origin, step, 1.0 / step)
                } else {
                    (0, 0)
                };
                assert_eq!(
                    (ql[k], qh[k]),
                    expect,
                    "case {case} slot {k}: {lo:?} {hi:?}"
                );
            }
        }
    }

    /// A box one ulp wide, or near the largest floats, gets a grid that reaches its end in a
    /// few steps and contains it.
    #[test]
    fn grids_reach_their_end_for_any_extent() {
        for lo in [1.999f32, -1.0, 0.0, 1e-30, 3e38, -3.4e38, 1e7] {
            for ulps in [1, 2, 3, 1000] {
                let mut hi = lo;
                for _ in 0..ulps {
                    hi = hi.next_up();
                }
                let step = grid_step(lo, hi);
                assert!(lo + 255.0 * step >= hi, "{lo} {hi}: step {step}");
                let (ql, qh) = quantize(lo, hi, lo, step, 1.0 / step);
                assert!(lo + ql as f32 * step <= lo && lo + qh as f32 * step >= hi);
            }
        }
        let step = grid_step(-3.4e38, 3.4e38);
        assert!(step.is_finite() && -3.4e38 + 255.0 * step >= 3.4e38);
    }
}
