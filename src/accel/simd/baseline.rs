//! [`Lanes8`] as two four-lane halves (`glam::Vec4`: SSE2 on x86-64, scalar elsewhere), and
//! [`Floats`] as one `glam::Vec4`.

use super::{Floats, Lanes8};
use glam::{BVec4A, Vec4};

// SAFETY: glam's `Vec4` runs on every CPU (SSE2 is in the x86-64 baseline).
unsafe impl Floats for Vec4 {
    const LANES: usize = 4;
    type Mask = BVec4A;
    #[inline(always)]
    unsafe fn splat(x: f32) -> Self {
        Vec4::splat(x)
    }
    #[inline(always)]
    unsafe fn from_slice(x: &[f32]) -> Self {
        Vec4::from_slice(x)
    }
    #[inline(always)]
    unsafe fn from_array<const N: usize>(v: [f32; N]) -> Self {
        const { assert!(N >= 4, "four values") };
        Vec4::new(v[0], v[1], v[2], v[3])
    }
    #[inline(always)]
    unsafe fn transpose3<const N: usize>(v: &[&glam::Vec3A; N]) -> [Self; 3] {
        const { assert!(N >= 4, "four vectors") };
        let m = glam::Mat4::from_cols(
            v[0].extend(0.0),
            v[1].extend(0.0),
            v[2].extend(0.0),
            v[3].extend(0.0),
        )
        .transpose();
        [m.x_axis, m.y_axis, m.z_axis]
    }
    #[inline(always)]
    fn write_to(self, out: &mut [f32]) {
        self.write_to_slice(out)
    }
    #[inline(always)]
    fn compress(self, bits: u32, out: &mut [f32]) {
        assert!(out.len() >= 4, "room for four values");
        let mut front = 0;
        for (i, x) in self.to_array().into_iter().enumerate() {
            if bits & (1 << i) != 0 {
                out[front] = x;
                front += 1;
            }
        }
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        Vec4::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> Self {
        Vec4::abs(self)
    }
    #[inline(always)]
    fn copysign(self, sign: Self) -> Self {
        Vec4::copysign(self, sign)
    }
    #[inline(always)]
    fn max(self, b: Self) -> Self {
        Vec4::max(self, b)
    }
    #[inline(always)]
    fn cmpge(self, b: Self) -> BVec4A {
        Vec4::cmpge(self, b)
    }
    #[inline(always)]
    fn cmple(self, b: Self) -> BVec4A {
        Vec4::cmple(self, b)
    }
    #[inline(always)]
    fn cmpgt(self, b: Self) -> BVec4A {
        Vec4::cmpgt(self, b)
    }
    #[inline(always)]
    fn cmplt(self, b: Self) -> BVec4A {
        Vec4::cmplt(self, b)
    }
    #[inline(always)]
    fn cmpne(self, b: Self) -> BVec4A {
        Vec4::cmpne(self, b)
    }
    #[inline(always)]
    fn select(m: BVec4A, a: Self, b: Self) -> Self {
        Vec4::select(m, a, b)
    }
    #[inline(always)]
    fn any(m: BVec4A) -> bool {
        m.any()
    }
    #[inline(always)]
    fn all(m: BVec4A) -> bool {
        m.all()
    }
    #[inline(always)]
    fn bitmask(m: BVec4A) -> u32 {
        m.bitmask()
    }
    #[inline(always)]
    fn signs_differ(a: Self, b: Self, c: Self) -> BVec4A {
        let sign = |v: Vec4| v.to_array().map(|x| x.to_bits() >> 31);
        let (a, b, c) = (sign(a), sign(b), sign(c));
        let d = |i: usize| a[i] != b[i] || a[i] != c[i];
        BVec4A::new(d(0), d(1), d(2), d(3))
    }
    type Axis = (BVec4A, BVec4A);
    #[inline(always)]
    fn axis(x: BVec4A, y: BVec4A) -> (BVec4A, BVec4A) {
        (x, y)
    }
    #[inline(always)]
    fn pick(v: &[f32; 4], (x, y): (BVec4A, BVec4A)) -> Self {
        let [a, b, c, _] = v.map(Vec4::splat);
        Vec4::select(x, a, Vec4::select(y, b, c))
    }
}

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
    unsafe fn load(x: &[f32; 8]) -> Self {
        Halves([Vec4::from_slice(&x[..4]), Vec4::from_slice(&x[4..])])
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
