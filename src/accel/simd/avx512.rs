//! [`Floats`] in one AVX-512 register: sixteen lanes, with a mask register per comparison.
//!
//! As for AVX2 ([`super::avx2`]), the constructors are unsafe (their caller must have found
//! AVX-512F, [`super::Isa::available`]), every other operation takes a value, and the methods
//! are `#[inline(always)]` without a target feature of their own, so that they inline into
//! the AVX-512 copies of the batched queries and of the Global shader's lanes kernel. Only
//! AVX-512F instructions are used (the sign-bit operations through its integer `and`, `or`
//! and `xor`), so any AVX-512 CPU runs them. The node test of the wide BVH stays on AVX2's
//! eight lanes (a node has eight children).

use super::{Floats, MAX_LANES};
use std::arch::x86_64::*;
use std::ops::{Add, BitAnd, BitOr, Div, Mul, Neg, Not, Sub};

/// Sixteen `f32` lanes for the shape tests ([`Floats`]). A value is made only by an unsafe
/// constructor whose caller found AVX-512F, so the safe operations on it run only on such a
/// CPU.
#[derive(Clone, Copy, Debug)]
pub struct F16(__m512);

/// Sixteen lane flags: an AVX-512 mask register, bit `i` for lane `i`.
#[derive(Clone, Copy, Debug)]
pub struct M16(__mmask16);

// SAFETY (of the `unsafe` blocks from here on): an `F16` exists, so AVX-512F was found (the
// only constructors are the unsafe `Floats::splat`, `from_slice`, `from_array` and
// `transpose3`, and the operations below, which take a value). The intrinsics only compute on
// registers, except the marked loads and stores. `M16` is a plain bit set, and `Axis16` sixteen
// indices, but each is made only from `F16`s (comparisons, then `Floats::axis`), so it too
// shows that AVX-512F was found.
macro_rules! binary {
    ($trait:ident, $method:ident, $intrinsic:ident) => {
        impl $trait for F16 {
            type Output = F16;
            #[inline(always)]
            fn $method(self, b: F16) -> F16 {
                F16(unsafe { $intrinsic(self.0, b.0) })
            }
        }
    };
}
binary!(Add, add, _mm512_add_ps);
binary!(Sub, sub, _mm512_sub_ps);
binary!(Mul, mul, _mm512_mul_ps);
binary!(Div, div, _mm512_div_ps);

impl BitAnd for M16 {
    type Output = M16;
    #[inline(always)]
    fn bitand(self, b: M16) -> M16 {
        M16(self.0 & b.0)
    }
}

impl BitOr for M16 {
    type Output = M16;
    #[inline(always)]
    fn bitor(self, b: M16) -> M16 {
        M16(self.0 | b.0)
    }
}

impl Not for M16 {
    type Output = M16;
    #[inline(always)]
    fn not(self) -> M16 {
        M16(!self.0)
    }
}

/// The sign bit of every lane.
#[inline(always)]
fn sign_bits() -> __m512i {
    // SAFETY: only called on values of `F16` (see above).
    unsafe { _mm512_set1_epi32(i32::MIN) }
}

impl Neg for F16 {
    type Output = F16;
    /// The sign bit flipped, as glam's `Vec4` negates.
    #[inline(always)]
    fn neg(self) -> F16 {
        F16(unsafe {
            _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(self.0), sign_bits()))
        })
    }
}

impl F16 {
    #[inline(always)]
    fn cmp<const P: i32>(self, b: F16) -> M16 {
        M16(unsafe { _mm512_cmp_ps_mask::<P>(self.0, b.0) })
    }

    /// The lanes' bits as integers.
    #[inline(always)]
    fn bits(self) -> __m512i {
        unsafe { _mm512_castps_si512(self.0) }
    }
}

// SAFETY: `splat`, `from_slice`, `from_array` and `transpose3` are the only constructors and
// are unsafe, with AVX-512F as the caller's duty; see above for the rest.
unsafe impl Floats for F16 {
    const LANES: usize = 16;
    type Mask = M16;
    #[inline(always)]
    unsafe fn splat(x: f32) -> Self {
        F16(unsafe { _mm512_set1_ps(x) })
    }
    #[inline(always)]
    unsafe fn from_slice(x: &[f32]) -> Self {
        assert!(x.len() >= 16, "sixteen values");
        // The load reads the first 64 bytes of `x`.
        F16(unsafe { _mm512_loadu_ps(x.as_ptr()) })
    }
    #[inline(always)]
    unsafe fn from_array<const N: usize>(v: [f32; N]) -> Self {
        const { assert!(N >= 16, "sixteen values") };
        F16(unsafe {
            _mm512_setr_ps(
                v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11], v[12],
                v[13], v[14], v[15],
            )
        })
    }
    #[inline(always)]
    unsafe fn transpose3<const N: usize>(v: &[&glam::Vec3A; N]) -> [Self; 3] {
        const { assert!(N >= 16, "sixteen vectors") };
        // Vectors i, i + 4, i + 8 and i + 12 share a register (a 128-bit quarter each); a
        // 4x4 transposition within every quarter at once then puts vector i's coordinates
        // in lane i.
        unsafe {
            let r = |i: usize| {
                let q = |k: usize| -> __m128 { (*v[i + 4 * k]).into() };
                let lo = _mm256_set_m128(q(1), q(0));
                let hi = _mm256_set_m128(q(3), q(2));
                // (The 256-bit insert of AVX-512F is the `f64` one; bits move unchanged.)
                let wide = _mm512_castps_pd(_mm512_castps256_ps512(lo));
                _mm512_castpd_ps(_mm512_insertf64x4::<1>(wide, _mm256_castps_pd(hi)))
            };
            let (r0, r1, r2, r3) = (r(0), r(1), r(2), r(3));
            let t0 = _mm512_unpacklo_ps(r0, r1); // x0 x1 y0 y1
            let t1 = _mm512_unpackhi_ps(r0, r1); // z0 z1 w0 w1
            let t2 = _mm512_unpacklo_ps(r2, r3); // x2 x3 y2 y3
            let t3 = _mm512_unpackhi_ps(r2, r3); // z2 z3 w2 w3
            [
                F16(_mm512_shuffle_ps::<0b01_00_01_00>(t0, t2)),
                F16(_mm512_shuffle_ps::<0b11_10_11_10>(t0, t2)),
                F16(_mm512_shuffle_ps::<0b01_00_01_00>(t1, t3)),
            ]
        }
    }
    #[inline(always)]
    fn write_to(self, out: &mut [f32]) {
        assert!(out.len() >= 16, "room for sixteen values");
        // The store writes the first 64 bytes of `out`.
        unsafe { _mm512_storeu_ps(out.as_mut_ptr(), self.0) }
    }
    #[inline(always)]
    fn compress(self, bits: u32, out: &mut [f32]) {
        assert!(out.len() >= 16, "room for sixteen values");
        // The lanes of `bits` moved to the front in a register (`vcompressps`; the memory
        // form is slow on some CPUs), then all sixteen stored: the first 64 bytes of `out`.
        unsafe {
            let packed = _mm512_maskz_compress_ps(bits as __mmask16, self.0);
            _mm512_storeu_ps(out.as_mut_ptr(), packed)
        }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        F16(unsafe { _mm512_sqrt_ps(self.0) })
    }
    #[inline(always)]
    fn abs(self) -> Self {
        F16(unsafe { _mm512_castsi512_ps(_mm512_andnot_si512(sign_bits(), self.bits())) })
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        unsafe {
            let m = sign_bits();
            F16(_mm512_castsi512_ps(_mm512_or_si512(
                _mm512_and_si512(sign.bits(), m),
                _mm512_andnot_si512(m, self.bits()),
            )))
        }
    }
    #[inline(always)]
    fn max(self, b: Self) -> Self {
        F16(unsafe { _mm512_max_ps(self.0, b.0) })
    }
    #[inline(always)]
    fn cmpge(self, b: Self) -> M16 {
        self.cmp::<_CMP_GE_OQ>(b)
    }
    #[inline(always)]
    fn cmple(self, b: Self) -> M16 {
        self.cmp::<_CMP_LE_OQ>(b)
    }
    #[inline(always)]
    fn cmpgt(self, b: Self) -> M16 {
        self.cmp::<_CMP_GT_OQ>(b)
    }
    #[inline(always)]
    fn cmplt(self, b: Self) -> M16 {
        self.cmp::<_CMP_LT_OQ>(b)
    }
    #[inline(always)]
    fn cmpne(self, b: Self) -> M16 {
        self.cmp::<_CMP_NEQ_UQ>(b)
    }
    #[inline(always)]
    fn select(m: M16, a: Self, b: Self) -> Self {
        F16(unsafe { _mm512_mask_blend_ps(m.0, b.0, a.0) })
    }
    #[inline(always)]
    fn any(m: M16) -> bool {
        m.0 != 0
    }
    #[inline(always)]
    fn all(m: M16) -> bool {
        m.0 == 0xffff
    }
    #[inline(always)]
    fn bitmask(m: M16) -> u32 {
        u32::from(m.0)
    }
    #[inline(always)]
    fn signs_differ(a: Self, b: Self, c: Self) -> M16 {
        // A sign bit set in `(a ^ b) | (a ^ c)`.
        // SAFETY: an `F16` exists (see above).
        unsafe {
            let (a, b, c) = (a.bits(), b.bits(), c.bits());
            let x = _mm512_or_si512(_mm512_xor_si512(a, b), _mm512_xor_si512(a, c));
            M16(_mm512_test_epi32_mask(x, sign_bits()))
        }
    }
    type Axis = Axis16;
    #[inline(always)]
    fn axis(x: M16, y: M16) -> Axis16 {
        // SAFETY: an `M16` comes only from comparing `F16`s, so AVX-512F was found.
        unsafe {
            let (zero, one, two) = (
                _mm512_set1_epi32(0),
                _mm512_set1_epi32(1),
                _mm512_set1_epi32(2),
            );
            Axis16(_mm512_mask_blend_epi32(
                x.0,
                _mm512_mask_blend_epi32(y.0, two, one),
                zero,
            ))
        }
    }
    #[inline(always)]
    fn pick(v: &[f32; 4], axis: Axis16) -> Self {
        // The four values in every 128-bit quarter (one load), then each lane's by its index.
        // SAFETY: an `Axis16` comes only from `F16`s (see above); the load reads the 16
        // bytes of `v`.
        unsafe {
            let table = _mm512_broadcast_f32x4(_mm_loadu_ps(v.as_ptr()));
            F16(_mm512_permutexvar_ps(axis.0, table))
        }
    }
}

/// Sixteen coordinate indices (0, 1 or 2), one per lane ([`Floats::axis`]).
#[derive(Clone, Copy, Debug)]
pub struct Axis16(__m512i);

const _: () = assert!(MAX_LANES >= 16, "the kernels' arrays hold sixteen lanes");
