//! The per-pixel random number generator.

use rand_core::Rng;
use rand_pcg::Pcg32;

/// A deterministic stream of uniform numbers for one (scene seed, pixel, sample) triple.
///
/// The stream depends only on that triple, never on which thread renders the pixel or in which
/// order tiles run, so renders are bit-identical for any thread count.
pub struct Sampler {
    rng: Pcg32,
}

/// SplitMix64's finaliser: a bijective 64-bit mix.
#[inline]
pub fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Sampler {
    /// The stream for sample `sample` of pixel `pixel` (row-major index) under `seed`.
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Self {
        let state = mix(mix(mix(seed) ^ pixel) ^ sample.rotate_left(32));
        Sampler {
            rng: Pcg32::new(state, 0x0a02_bdbf_7bb3_c0a7),
        }
    }

    /// A uniform number in `[0, 1)` with 24 random bits.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        (self.rng.next_u32() >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
    }

    /// A uniform number in `[0, 1)` with 53 random bits (two draws), for choices among many
    /// options whose probabilities are finer than `next_f32`'s grid of 2^-24.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        let bits = ((self.rng.next_u32() as u64) << 21) ^ (self.rng.next_u32() as u64 >> 11);
        bits as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Two uniform numbers in `[0, 1)`.
    #[inline]
    pub fn next_2d(&mut self) -> (f32, f32) {
        (self.next_f32(), self.next_f32())
    }

    /// A uniform integer in `[0, n)` for `n > 0`.
    #[inline]
    pub fn next_below(&mut self, n: u32) -> u32 {
        ((self.rng.next_u32() as u64 * n as u64) >> 32) as u32
    }
}
