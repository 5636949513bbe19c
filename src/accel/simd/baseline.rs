//! [`Lanes8`] as two four-lane halves (`glam::Vec4`: SSE2 on x86-64, scalar elsewhere).

use super::Lanes8;
use glam::Vec4;

/// Eight lanes in two `Vec4`s, lanes 0 to 3 then 4 to 7.
#[derive(Clone, Copy, Debug)]
pub struct Halves(pub [Vec4; 2]);

/// Four grid coordinates as floats: two unpacks and a conversion with SSE2, four conversions
/// elsewhere.
#[inline(always)]
fn widen4(q: [u8; 4]) -> Vec4 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{
            _mm_cvtepi32_ps, _mm_cvtsi32_si128, _mm_setzero_si128, _mm_unpacklo_epi8,
            _mm_unpacklo_epi16,
        };
        // SAFETY: SSE2 is in the x86-64 baseline; these intrinsics only move and convert
        // register values.
        unsafe {
            let zero = _mm_setzero_si128();
            let bytes = _mm_cvtsi32_si128(i32::from_le_bytes(q));
            let words = _mm_unpacklo_epi8(bytes, zero);
            Vec4::from(_mm_cvtepi32_ps(_mm_unpacklo_epi16(words, zero)))
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        Vec4::new(q[0] as f32, q[1] as f32, q[2] as f32, q[3] as f32)
    }
}

impl Halves {
    #[inline(always)]
    fn zip(self, b: Halves, f: impl Fn(Vec4, Vec4) -> Vec4) -> Halves {
        Halves([f(self.0[0], b.0[0]), f(self.0[1], b.0[1])])
    }
}

// SAFETY (of every method): SSE2 is in the x86-64 baseline, so these run on every CPU; they
// are unsafe only because the trait's AVX2 variant needs to be.
impl Lanes8 for Halves {
    #[inline(always)]
    unsafe fn splat(x: f32) -> Self {
        Halves([Vec4::splat(x); 2])
    }
    #[inline(always)]
    unsafe fn widen(q: &[u8; 8]) -> Self {
        Halves([
            widen4([q[0], q[1], q[2], q[3]]),
            widen4([q[4], q[5], q[6], q[7]]),
        ])
    }
    #[inline(always)]
    unsafe fn add(self, b: Self) -> Self {
        self.zip(b, |x, y| x + y)
    }
    #[inline(always)]
    unsafe fn sub(self, b: Self) -> Self {
        self.zip(b, |x, y| x - y)
    }
    #[inline(always)]
    unsafe fn mul(self, b: Self) -> Self {
        self.zip(b, |x, y| x * y)
    }
    #[inline(always)]
    unsafe fn min(self, b: Self) -> Self {
        self.zip(b, Vec4::min)
    }
    #[inline(always)]
    unsafe fn max(self, b: Self) -> Self {
        self.zip(b, Vec4::max)
    }
    #[inline(always)]
    unsafe fn le(self, b: Self) -> u32 {
        self.0[0].cmple(b.0[0]).bitmask() | self.0[1].cmple(b.0[1]).bitmask() << 4
    }
    #[inline(always)]
    unsafe fn to_array(self) -> [f32; 8] {
        let (a, b) = (self.0[0].to_array(), self.0[1].to_array());
        [a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]]
    }
    #[inline(always)]
    unsafe fn ne_u32(x: &[u32; 8], v: u32) -> u32 {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{
                __m128i, _mm_castsi128_ps, _mm_cmpeq_epi32, _mm_loadu_si128, _mm_movemask_ps,
                _mm_set1_epi32,
            };
            // SAFETY: SSE2 is in the x86-64 baseline; the loads read the 32 bytes of `x`.
            unsafe {
                let v = _mm_set1_epi32(v as i32);
                let half = |k: usize| {
                    let lanes = _mm_loadu_si128(x.as_ptr().add(4 * k) as *const __m128i);
                    _mm_movemask_ps(_mm_castsi128_ps(_mm_cmpeq_epi32(lanes, v))) as u32
                };
                !(half(0) | half(1) << 4) & 0xff
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            (0..8).fold(0, |m, i| m | ((x[i] != v) as u32) << i)
        }
    }
}
