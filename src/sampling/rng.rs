//! The independent sampler: a per-sample stream of PCG32 numbers.

/// A deterministic stream of uniform numbers for one (scene seed, pixel, sample) triple.
///
/// The stream depends only on that triple, never on which thread renders the pixel or in which
/// order tiles run, so renders are bit-identical for any thread count. The generator is
/// O'Neill's PCG32 (XSH RR 64/32: "PCG: A Family of Simple Fast Space-Efficient Statistically
/// Good Algorithms for Random Number Generation", 2014), the numbers of `rand_pcg::Pcg32`;
/// [`PcgLanes`] draws several of them side by side.
#[derive(Clone, Debug)]
pub struct Pcg32 {
    /// The LCG's state.
    state: u64,
    /// The LCG's increment (odd): which of PCG32's streams.
    inc: u64,
}

/// PCG32's LCG multiplier (Knuth's MMIX constant).
const MULTIPLIER: u64 = 6_364_136_223_846_793_005;

/// The LCG's next state: `state a + inc (mod 2^64)`.
#[inline(always)]
fn step(state: u64, inc: u64) -> u64 {
    state.wrapping_mul(MULTIPLIER).wrapping_add(inc)
}

/// PCG32's output of a state, XSH RR: the high bits xorshifted, then rotated by the top five.
#[inline(always)]
fn output(state: u64) -> u32 {
    let rot = (state >> 59) as u32;
    let xsh = (((state >> 18) ^ state) >> 27) as u32;
    xsh.rotate_right(rot)
}

/// `next_f32` of 32 random bits: the top 24 on a grid of `2^-24`.
#[inline(always)]
pub(super) fn to_f32(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// `next_f64` of two draws: 53 bits on a grid of `2^-53`.
#[inline(always)]
pub(super) fn to_f64(a: u32, b: u32) -> f64 {
    let bits = ((a as u64) << 21) ^ (b as u64 >> 11);
    bits as f64 * (1.0 / (1u64 << 53) as f64)
}

/// SplitMix64's finaliser: a bijective 64-bit mix.
#[inline]
pub fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Pcg32 {
    /// The stream for sample `sample` of pixel `pixel` (row-major index) under `seed`.
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Self {
        let state = mix(mix(mix(seed) ^ pixel) ^ sample.rotate_left(32));
        Pcg32::seeded(state, 0x0a02_bdbf_7bb3_c0a7)
    }

    /// PCG32 seeded as its reference `pcg32_srandom_r(initstate, initseq)` seeds it (and
    /// `rand_pcg::Pcg32::new`).
    fn seeded(initstate: u64, initseq: u64) -> Self {
        let inc = (initseq << 1) | 1;
        Pcg32 {
            state: step(initstate.wrapping_add(inc), inc),
            inc,
        }
    }

    /// 32 random bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = step(old, self.inc);
        output(old)
    }

    /// A uniform number in `[0, 1)` with 24 random bits.
    #[inline]
    pub fn next_f32(&mut self) -> f32 {
        to_f32(self.next_u32())
    }

    /// Two numbers of [`Pcg32::next_f64`], in order.
    #[inline]
    pub fn next_2d_f64(&mut self) -> (f64, f64) {
        let x = self.next_f64();
        (x, self.next_f64())
    }

    /// A uniform number in `[0, 1)` with 53 random bits (two draws), for choices among many
    /// options whose probabilities are finer than `next_f32`'s grid of 2^-24.
    #[inline]
    pub fn next_f64(&mut self) -> f64 {
        let a = self.next_u32();
        to_f64(a, self.next_u32())
    }

    /// Two uniform numbers in `[0, 1)`.
    #[inline]
    pub fn next_2d(&mut self) -> (f32, f32) {
        (self.next_f32(), self.next_f32())
    }

    /// A uniform integer in `[0, n)` for `n > 0`.
    #[inline]
    pub fn next_below(&mut self, n: u32) -> u32 {
        ((self.next_u32() as u64 * n as u64) >> 32) as u32
    }
}

/// Up to [`PcgLanes::MAX`] samplers drawn side by side, lane `i` advancing as sampler `i`'s
/// own [`Pcg32`] methods would: the same numbers, in lanes. Each draw is a loop over fixed
/// arrays without branches, which the compiler turns into the SIMD instructions of the
/// function it is inlined in (Path's lanes, `shader::path::lanes`).
#[derive(Clone, Copy)]
pub struct PcgLanes {
    state: [u64; PcgLanes::MAX],
    inc: [u64; PcgLanes::MAX],
}

impl PcgLanes {
    /// The most lanes.
    pub const MAX: usize = 16;

    /// The streams of `samplers` (at most [`PcgLanes::MAX`]), lane `i` from `samplers[i]`;
    /// lanes past them hold a stream of their own that nobody reads.
    #[inline(always)]
    pub fn load<'a>(samplers: impl Iterator<Item = &'a Pcg32>) -> PcgLanes {
        let mut s = PcgLanes {
            state: [0; PcgLanes::MAX],
            inc: [1; PcgLanes::MAX],
        };
        for (i, sampler) in samplers.take(PcgLanes::MAX).enumerate() {
            (s.state[i], s.inc[i]) = (sampler.state, sampler.inc);
        }
        s
    }

    /// Lane `i`'s sampler, where it has got to.
    #[inline(always)]
    pub fn sampler(&self, i: usize) -> Pcg32 {
        Pcg32 {
            state: self.state[i],
            inc: self.inc[i],
        }
    }

    /// [`Pcg32::next_u32`] in the first `lanes` lanes.
    #[inline(always)]
    pub fn next_u32(&mut self, lanes: usize) -> [u32; PcgLanes::MAX] {
        let mut out = [0; PcgLanes::MAX];
        let lanes_of = out.iter_mut().zip(&mut self.state).zip(&self.inc);
        for ((out, state), &inc) in lanes_of.take(lanes) {
            let old = *state;
            *state = step(old, inc);
            *out = output(old);
        }
        out
    }

    /// [`Pcg32::next_f32`] in the first `lanes` lanes.
    #[inline(always)]
    pub fn next_f32(&mut self, lanes: usize) -> [f32; PcgLanes::MAX] {
        self.next_u32(lanes).map(to_f32)
    }

    /// [`Pcg32::next_2d`] in the first `lanes` lanes: the two coordinates' arrays.
    #[inline(always)]
    pub fn next_2d(&mut self, lanes: usize) -> ([f32; PcgLanes::MAX], [f32; PcgLanes::MAX]) {
        let x = self.next_f32(lanes);
        (x, self.next_f32(lanes))
    }

    /// [`Pcg32::next_2d_f64`] in lane `i` alone.
    #[inline(always)]
    pub fn next_2d_f64_at(&mut self, i: usize) -> (f64, f64) {
        let mut s = self.sampler(i);
        let v = s.next_2d_f64();
        self.state[i] = s.state;
        v
    }

    /// [`Pcg32::next_f64`] in the first `lanes` lanes.
    #[inline(always)]
    pub fn next_f64(&mut self, lanes: usize) -> [f64; PcgLanes::MAX] {
        let (a, b) = (self.next_u32(lanes), self.next_u32(lanes));
        std::array::from_fn(|i| to_f64(a[i], b[i]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first outputs of PCG32's reference demo (`pcg32-demo`, seeded with 42 and 54).
    #[test]
    fn pcg32_gives_the_reference_numbers() {
        let mut s = Pcg32::seeded(42, 54);
        let got: Vec<u32> = (0..6).map(|_| s.next_u32()).collect();
        assert_eq!(
            got,
            [
                0xa15c02b7, 0x7b47f409, 0xba1d3330, 0x83d2f293, 0xbfa4784b, 0xcbed606e
            ]
        );
    }

    /// `PcgLanes` draws each lane's numbers: the samplers' own, lane by lane, in every width.
    #[test]
    fn streams_draw_each_samplers_numbers() {
        for lanes in [4, 8, 16] {
            let samplers: Vec<Pcg32> = (0..lanes).map(|k| Pcg32::new(7, k, 3 * k)).collect();
            let mut streams = PcgLanes::load(samplers.iter());
            let mut own = samplers.clone();
            for _ in 0..5 {
                let (u, x, y) = (
                    streams.next_u32(lanes as usize),
                    streams.next_f32(lanes as usize),
                    streams.next_f64(lanes as usize),
                );
                for (i, s) in own.iter_mut().enumerate() {
                    assert_eq!(u[i], s.next_u32());
                    assert_eq!(x[i].to_bits(), s.next_f32().to_bits());
                    assert_eq!(y[i].to_bits(), s.next_f64().to_bits());
                }
            }
            // A draw of one lane alone.
            let last = lanes as usize - 1;
            let (a, b) = streams.next_2d_f64_at(last);
            let mut copy = own[last].clone();
            let (c, d) = own[last].next_2d_f64();
            assert_eq!((a.to_bits(), b.to_bits()), (c.to_bits(), d.to_bits()));
            // Two `next_f64` in order: the numbers environment samples drew before it.
            let (e, f) = (copy.next_f64(), copy.next_f64());
            assert_eq!((c.to_bits(), d.to_bits()), (e.to_bits(), f.to_bits()));
            for (i, s) in own.iter().enumerate() {
                assert_eq!(streams.sampler(i).state, s.state);
            }
        }
    }
}
