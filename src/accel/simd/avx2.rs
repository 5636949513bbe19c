//! [`Lanes8`] and [`Floats`] in one AVX2 register.
//!
//! Every [`Lanes8`] method, and every [`Floats`] constructor, is unsafe: its caller must have
//! found AVX2 ([`super::Isa::available`]); the other [`Floats`] operations take a value, which
//! exists only where that was done. The methods are `#[inline(always)]` without a target
//! feature of their own, so that they and the intrinsics in them inline into the AVX2 copies
//! of the BVH traversals and of the batched queries (which enable AVX2); a closure between the
//! two would be compiled without it and keep every intrinsic a call, so the node test and the
//! lane tests have none.

use super::{Floats, Lanes8};
use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Eight lanes in a `__m256`.
#[derive(Clone, Copy, Debug)]
pub struct Avx2(__m256);

// SAFETY (of every `unsafe` block below): the caller found AVX2, as each method requires.
impl Lanes8 for Avx2 {
    #[inline(always)]
    unsafe fn splat(x: f32) -> Self {
        Avx2(unsafe { _mm256_set1_ps(x) })
    }
    #[inline(always)]
    unsafe fn widen(q: &[u8; 8]) -> Self {
        // The load reads the 8 bytes of `q`.
        unsafe {
            let bytes = _mm_loadl_epi64(q.as_ptr() as *const __m128i);
            Avx2(_mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(bytes)))
        }
    }
    #[inline(always)]
    unsafe fn load(x: &[f32; 8]) -> Self {
        // The load reads the 32 bytes of `x`.
        Avx2(unsafe { _mm256_loadu_ps(x.as_ptr()) })
    }
    #[inline(always)]
    unsafe fn add(self, b: Self) -> Self {
        Avx2(unsafe { _mm256_add_ps(self.0, b.0) })
    }
    #[inline(always)]
    unsafe fn sub(self, b: Self) -> Self {
        Avx2(unsafe { _mm256_sub_ps(self.0, b.0) })
    }
    #[inline(always)]
    unsafe fn mul(self, b: Self) -> Self {
        Avx2(unsafe { _mm256_mul_ps(self.0, b.0) })
    }
    #[inline(always)]
    unsafe fn min(self, b: Self) -> Self {
        Avx2(unsafe { _mm256_min_ps(self.0, b.0) })
    }
    #[inline(always)]
    unsafe fn max(self, b: Self) -> Self {
        Avx2(unsafe { _mm256_max_ps(self.0, b.0) })
    }
    #[inline(always)]
    unsafe fn le(self, b: Self) -> u32 {
        unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(self.0, b.0)) as u32 }
    }
    #[inline(always)]
    unsafe fn to_array(self) -> [f32; 8] {
        let mut out = [0.0; 8];
        // The store writes the 32 bytes of `out`.
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), self.0) };
        out
    }
    #[inline(always)]
    unsafe fn ne_u32(x: &[u32; 8], v: u32) -> u32 {
        // The load reads the 32 bytes of `x`.
        unsafe {
            let lanes = _mm256_loadu_si256(x.as_ptr() as *const __m256i);
            let eq = _mm256_cmpeq_epi32(lanes, _mm256_set1_epi32(v as i32));
            !(_mm256_movemask_ps(_mm256_castsi256_ps(eq)) as u32) & 0xff
        }
    }
}

/// Eight `f32` lanes for the shape tests ([`Floats`]). A value is made only by an unsafe
/// constructor whose caller found AVX2, so the safe operations on it run only on such a CPU.
#[derive(Clone, Copy, Debug)]
pub struct F8(__m256);

/// Eight lane flags, all bits set or clear.
#[derive(Clone, Copy, Debug)]
pub struct M8(__m256);

// SAFETY (of the `unsafe` blocks from here on): an `F8` or `M8` exists, so AVX2 was found (the
// only constructors are the unsafe `Floats::splat`, `from_slice`, `from_array` and
// `transpose3`, and the operations
// below, which take a value). The intrinsics only compute on registers, except the marked
// loads and stores.
macro_rules! binary {
    ($trait:ident, $method:ident, $t:ident, $intrinsic:ident) => {
        impl $trait for $t {
            type Output = $t;
            #[inline(always)]
            fn $method(self, b: $t) -> $t {
                $t(unsafe { $intrinsic(self.0, b.0) })
            }
        }
    };
}
binary!(Add, add, F8, _mm256_add_ps);
binary!(Sub, sub, F8, _mm256_sub_ps);
binary!(Mul, mul, F8, _mm256_mul_ps);
binary!(Div, div, F8, _mm256_div_ps);
binary!(BitAnd, bitand, M8, _mm256_and_ps);
binary!(BitOr, bitor, M8, _mm256_or_ps);

impl Neg for F8 {
    type Output = F8;
    /// The sign bit flipped, as glam's `Vec4` negates.
    #[inline(always)]
    fn neg(self) -> F8 {
        F8(unsafe { _mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)) })
    }
}

impl Not for M8 {
    type Output = M8;
    #[inline(always)]
    fn not(self) -> M8 {
        M8(unsafe { _mm256_xor_ps(self.0, _mm256_castsi256_ps(_mm256_set1_epi32(-1))) })
    }
}

impl F8 {
    #[inline(always)]
    fn cmp<const P: i32>(self, b: F8) -> M8 {
        M8(unsafe { _mm256_cmp_ps::<P>(self.0, b.0) })
    }
}

/// For each set of lanes (a byte, bit `i` for lane `i`), the permutation that moves its lanes
/// to the front in order ([`Floats::compress`]); the other lanes follow in order.
static PACK: [[u32; 8]; 256] = {
    let mut table = [[0u32; 8]; 256];
    let mut bits = 0;
    while bits < 256 {
        let (mut front, mut i) = (0, 0);
        while i < 8 {
            if bits & (1 << i) != 0 {
                table[bits][front] = i as u32;
                front += 1;
            }
            i += 1;
        }
        let (mut back, mut i) = (front, 0);
        while i < 8 {
            if bits & (1 << i) == 0 {
                table[bits][back] = i as u32;
                back += 1;
            }
            i += 1;
        }
        bits += 1;
    }
    table
};

// SAFETY: `splat`, `from_slice`, `from_array` and `transpose3` are the only constructors and
// are unsafe, with AVX2 as the
// caller's duty; see above for the rest.
unsafe impl Floats for F8 {
    const LANES: usize = 8;
    type Mask = M8;
    #[inline(always)]
    unsafe fn splat(x: f32) -> Self {
        F8(unsafe { _mm256_set1_ps(x) })
    }
    #[inline(always)]
    unsafe fn from_slice(x: &[f32]) -> Self {
        assert!(x.len() >= 8, "eight values");
        // The load reads the first 32 bytes of `x`.
        F8(unsafe { _mm256_loadu_ps(x.as_ptr()) })
    }
    #[inline(always)]
    unsafe fn from_array<const N: usize>(v: [f32; N]) -> Self {
        const { assert!(N >= 8, "eight values") };
        F8(unsafe { _mm256_setr_ps(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]) })
    }
    #[inline(always)]
    unsafe fn transpose3<const N: usize>(v: &[&glam::Vec3A; N]) -> [Self; 3] {
        const { assert!(N >= 8, "eight vectors") };
        // Vectors i and i + 4 share a register (low and high half); a 4x4 transposition
        // within both halves at once then puts vector i's coordinates in lane i.
        unsafe {
            let r = |i: usize| {
                let (lo, hi): (__m128, __m128) = ((*v[i]).into(), (*v[i + 4]).into());
                _mm256_set_m128(hi, lo)
            };
            let (r0, r1, r2, r3) = (r(0), r(1), r(2), r(3));
            let t0 = _mm256_unpacklo_ps(r0, r1); // x0 x1 y0 y1
            let t1 = _mm256_unpackhi_ps(r0, r1); // z0 z1 w0 w1
            let t2 = _mm256_unpacklo_ps(r2, r3); // x2 x3 y2 y3
            let t3 = _mm256_unpackhi_ps(r2, r3); // z2 z3 w2 w3
            [
                F8(_mm256_shuffle_ps::<0b01_00_01_00>(t0, t2)),
                F8(_mm256_shuffle_ps::<0b11_10_11_10>(t0, t2)),
                F8(_mm256_shuffle_ps::<0b01_00_01_00>(t1, t3)),
            ]
        }
    }
    #[inline(always)]
    fn write_to(self, out: &mut [f32]) {
        assert!(out.len() >= 8, "room for eight values");
        // The store writes the first 32 bytes of `out`.
        unsafe { _mm256_storeu_ps(out.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn compress(self, bits: u32, out: &mut [f32]) {
        assert!(out.len() >= 8, "room for eight values");
        // The lanes of `bits` moved to the front by one permutation (a move of bits), then
        // all eight stored: the first 32 bytes of `out`.
        unsafe {
            let idx = _mm256_loadu_si256(PACK[(bits & 0xff) as usize].as_ptr().cast());
            let packed = _mm256_permutevar8x32_ps(self.0, idx);
            _mm256_storeu_ps(out.as_mut_ptr(), packed)
        }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        F8(unsafe { _mm256_sqrt_ps(self.0) })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        F8(unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), self.0) })
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        unsafe {
            let m = _mm256_set1_ps(-0.0);
            F8(_mm256_or_ps(
                _mm256_and_ps(sign.0, m),
                _mm256_andnot_ps(m, self.0),
            ))
        }
    }
    #[inline(always)]
    fn max(self, b: Self) -> Self {
        F8(unsafe { _mm256_max_ps(self.0, b.0) })
    }
    #[inline(always)]
    fn cmpge(self, b: Self) -> M8 {
        self.cmp::<_CMP_GE_OQ>(b)
    }
    #[inline(always)]
    fn cmple(self, b: Self) -> M8 {
        self.cmp::<_CMP_LE_OQ>(b)
    }
    #[inline(always)]
    fn cmpgt(self, b: Self) -> M8 {
        self.cmp::<_CMP_GT_OQ>(b)
    }
    #[inline(always)]
    fn cmplt(self, b: Self) -> M8 {
        self.cmp::<_CMP_LT_OQ>(b)
    }
    #[inline(always)]
    fn cmpne(self, b: Self) -> M8 {
        self.cmp::<_CMP_NEQ_UQ>(b)
    }
    #[inline(always)]
    fn select(m: M8, a: Self, b: Self) -> Self {
        F8(unsafe { _mm256_blendv_ps(b.0, a.0, m.0) })
    }
    #[inline(always)]
    fn any(m: M8) -> bool {
        unsafe { _mm256_movemask_ps(m.0) != 0 }
    }
    #[inline(always)]
    fn all(m: M8) -> bool {
        unsafe { _mm256_movemask_ps(m.0) == 0xff }
    }
    #[inline(always)]
    fn bitmask(m: M8) -> u32 {
        unsafe { _mm256_movemask_ps(m.0) as u32 }
    }
    #[inline(always)]
    fn signs_differ(a: Self, b: Self, c: Self) -> M8 {
        // A sign bit set in `(a ^ b) | (a ^ c)`, spread over its lane.
        unsafe {
            let x = _mm256_or_ps(_mm256_xor_ps(a.0, b.0), _mm256_xor_ps(a.0, c.0));
            M8(_mm256_castsi256_ps(_mm256_srai_epi32::<31>(
                _mm256_castps_si256(x),
            )))
        }
    }
    type Axis = (M8, M8);
    #[inline(always)]
    fn axis(x: M8, y: M8) -> (M8, M8) {
        (x, y)
    }
    #[inline(always)]
    fn pick(v: &[f32; 4], (x, y): (M8, M8)) -> Self {
        // SAFETY: an `M8` exists, so AVX2 was found.
        let (a, b, c) = unsafe {
            (
                F8(_mm256_set1_ps(v[0])),
                F8(_mm256_set1_ps(v[1])),
                F8(_mm256_set1_ps(v[2])),
            )
        };
        Self::select(x, a, Self::select(y, b, c))
    }
}
