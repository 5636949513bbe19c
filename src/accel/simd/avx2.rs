//! [`Lanes8`] in one AVX2 register.
//!
//! Every method is unsafe: its caller must have found AVX2 ([`super::Isa::available`]). The
//! methods are `#[inline(always)]` without a target feature of their own, so that they and the
//! intrinsics in them inline into the wide BVH's AVX2 traversals (which enable AVX2); a closure
//! between the two would be compiled without it and keep every intrinsic a call, so the node
//! test has none.

use super::Lanes8;
use std::arch::x86_64::*;

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
