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
/// Every method may use its instruction set: callers must have checked that the CPU runs it
/// (for [`Isa::Avx2`], [`Isa::available`]). The methods are unsafe so that the AVX2 ones can
/// be compiled with AVX2 enabled, and so inlined into the AVX2 traversals; a safe method
/// calling the intrinsics would stay a call per operation.
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
