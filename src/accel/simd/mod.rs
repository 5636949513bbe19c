//! Eight float lanes for the wide BVH's node test, in the instruction set the CPU has: the
//! closed set [`Isa`], one file per variant, chosen at run time.
//!
//! Every variant computes the same IEEE operations lane by lane (no fused multiply-add), so
//! the traversal's answers are bit-identical whichever runs; only the speed differs. The
//! build targets baseline x86-64, so a binary runs on any x86-64 CPU and takes AVX2 where
//! [`Isa::detect`] finds it, as Embree's ISA dispatch does.

#[cfg(target_arch = "x86_64")]
pub mod avx2;
pub mod baseline;

/// The instruction sets the node test is written for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// Two four-lane halves: SSE2 (part of every x86-64 CPU), or scalar code elsewhere.
    Baseline,
    /// One eight-lane AVX2 register (x86-64 only).
    Avx2,
}

impl Isa {
    /// The widest instruction set this CPU runs.
    pub fn detect() -> Isa {
        if Isa::Avx2.available() {
            Isa::Avx2
        } else {
            Isa::Baseline
        }
    }

    /// True if this CPU runs the instruction set.
    pub fn available(self) -> bool {
        match self {
            Isa::Baseline => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => std::arch::is_x86_feature_detected!("avx2"),
            #[cfg(not(target_arch = "x86_64"))]
            Isa::Avx2 => false,
        }
    }

    /// Every instruction set this CPU runs, baseline first.
    pub fn all_available() -> Vec<Isa> {
        [Isa::Baseline, Isa::Avx2]
            .into_iter()
            .filter(|isa| isa.available())
            .collect()
    }

    /// Its name, as the bench and `--isa` spell it.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Baseline => "baseline",
            Isa::Avx2 => "avx2",
        }
    }
}

impl Default for Isa {
    /// [`Isa::detect`].
    fn default() -> Isa {
        Isa::detect()
    }
}

/// Eight `f32` lanes: what the node test needs of a SIMD register.
///
/// Implementations must compute each operation exactly as IEEE single precision does, lane by
/// lane (the comparisons are ordered: false where a lane is NaN), so that the variants agree
/// to the bit.
///
/// # Safety
/// Every method may run instructions of its set, which only the caller can vouch for: callers
/// must have checked that the CPU runs it (for [`Isa::Avx2`], [`Isa::available`]). The
/// baseline's methods are unsafe only because the trait's are.
pub trait Lanes8: Copy {
    /// `x` in every lane.
    unsafe fn splat(x: f32) -> Self;
    /// Eight grid coordinates as floats (exact: a byte fits a float's significand).
    unsafe fn widen(q: &[u8; 8]) -> Self;
    /// Lane-wise `self + b`.
    unsafe fn add(self, b: Self) -> Self;
    /// Lane-wise `self - b`.
    unsafe fn sub(self, b: Self) -> Self;
    /// Lane-wise `self * b`.
    unsafe fn mul(self, b: Self) -> Self;
    /// Lane-wise minimum (`b` where either is NaN, as SSE's `minps`).
    unsafe fn min(self, b: Self) -> Self;
    /// Lane-wise maximum (`b` where either is NaN, as SSE's `maxps`).
    unsafe fn max(self, b: Self) -> Self;
    /// The lanes (bits 0 to 7) where `self <= b`.
    unsafe fn le(self, b: Self) -> u32;
    /// The lanes as an array.
    unsafe fn to_array(self) -> [f32; 8];
    /// The lanes (bits 0 to 7) of `x` that differ from `v`.
    unsafe fn ne_u32(x: &[u32; 8], v: u32) -> u32;
}

/// For tests that compare instruction sets: panics if the environment asks for all of them
/// (`RTIS_REQUIRE_AVX2=1`, which `.ci/run` sets) and the CPU lacks one, so that a CI machine
/// without AVX2 cannot pass by comparing the baseline with itself.
pub fn require_all_isas() {
    if std::env::var_os("RTIS_REQUIRE_AVX2").is_some_and(|v| v == "1") {
        assert!(
            Isa::Avx2.available(),
            "RTIS_REQUIRE_AVX2=1 but this CPU has no AVX2"
        );
    }
}

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::avx2::Avx2;
    use super::baseline::Halves;
    use super::*;

    /// Every lane operation gives the same bits in both instruction sets, on the values where
    /// implementations differ if they differ at all: NaN in either operand, zeros of both
    /// signs, infinities, equal operands, subnormals and bytes at both ends.
    #[test]
    fn every_lane_operation_agrees_bit_for_bit() {
        super::require_all_isas();
        if !Isa::Avx2.available() {
            eprintln!("no AVX2 here: nothing to compare");
            return;
        }
        let specials = [
            f32::NAN,
            -f32::NAN,
            0.0,
            -0.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            1.0,
            -1.0,
            1e-45,
            f32::MAX,
            -3.5,
            2.0,
        ];
        let n = specials.len();
        let lanes = |k: usize| -> [f32; 8] { std::array::from_fn(|i| specials[(k + 3 * i) % n]) };
        let bits = |v: [f32; 8]| v.map(f32::to_bits);
        for a in 0..n {
            for b in 0..n {
                let (x, y) = (lanes(a), lanes(b));
                // SAFETY: AVX2 is present (checked above); the baseline runs everywhere.
                unsafe {
                    let h = |v: [f32; 8]| {
                        Halves([
                            glam::Vec4::from_slice(&v[..4]),
                            glam::Vec4::from_slice(&v[4..]),
                        ])
                    };
                    let (hx, hy) = (h(x), h(y));
                    // An `Avx2` is a `__m256`: eight `f32` lanes in order.
                    let v = |v: [f32; 8]| std::mem::transmute::<[f32; 8], Avx2>(v);
                    let (vx, vy) = (v(x), v(y));
                    assert_eq!(bits(hx.add(hy).to_array()), bits(vx.add(vy).to_array()));
                    assert_eq!(bits(hx.sub(hy).to_array()), bits(vx.sub(vy).to_array()));
                    assert_eq!(bits(hx.mul(hy).to_array()), bits(vx.mul(vy).to_array()));
                    assert_eq!(bits(hx.min(hy).to_array()), bits(vx.min(vy).to_array()));
                    assert_eq!(bits(hx.max(hy).to_array()), bits(vx.max(vy).to_array()));
                    assert_eq!(hx.le(hy), vx.le(vy), "{x:?} <= {y:?}");
                    assert_eq!(
                        bits(Halves::splat(x[0]).to_array()),
                        bits(Avx2::splat(x[0]).to_array())
                    );
                }
            }
        }
        for q in [[0u8, 1, 2, 127, 128, 254, 255, 7], [255; 8], [0; 8]] {
            // SAFETY: as above.
            unsafe {
                assert_eq!(
                    bits(Halves::widen(&q).to_array()),
                    bits(Avx2::widen(&q).to_array())
                );
            }
        }
        for c in [
            [0u32, 1, u32::MAX, 5, u32::MAX, 0, 1 << 31, 2],
            [u32::MAX; 8],
            [3; 8],
        ] {
            // SAFETY: as above.
            unsafe {
                assert_eq!(
                    Halves::ne_u32(&c, u32::MAX),
                    Avx2::ne_u32(&c, u32::MAX),
                    "{c:?}"
                );
            }
        }
    }
}
