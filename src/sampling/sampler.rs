//! The samplers: where a sample's random numbers come from, one variant per file
//! (`rng.rs`, `sobol.rs`), and their lanes.

use super::rng::{Pcg32, PcgLanes};
use super::sobol::{Sobol, SobolLanes};

/// Which sampler a render draws its numbers from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SamplerKind {
    /// Independent uniform numbers (PCG32), as Mitsuba 3's `independent` (the default).
    #[default]
    Independent,
    /// Padded, Owen-scrambled Sobol' points: each draw stratified over a pixel's samples, as
    /// pbrt-v4's `PaddedSobolSampler`.
    Sobol,
}

/// One camera sample's random numbers: a stream that depends only on (scene seed, pixel,
/// sample), never on which thread renders the pixel or in which order tiles run, so renders
/// are bit-identical for any thread count.
#[derive(Clone, Debug)]
pub enum Sampler {
    /// [`SamplerKind::Independent`].
    Independent(Pcg32),
    /// [`SamplerKind::Sobol`].
    Sobol(Sobol),
}

impl Sampler {
    /// The independent stream of sample `sample` of pixel `pixel` (row-major index) under
    /// `seed`.
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Self {
        Sampler::Independent(Pcg32::new(seed, pixel, sample))
    }

    /// The stream of sample `sample` of pixel `pixel` under `seed` from the sampler `kind`.
    pub fn of(kind: SamplerKind, seed: u64, pixel: u64, sample: u64) -> Self {
        match kind {
            SamplerKind::Independent => Sampler::new(seed, pixel, sample),
            SamplerKind::Sobol => Sampler::Sobol(Sobol::new(seed, pixel, sample)),
        }
    }

    /// 32 random bits.
    #[inline(always)]
    pub fn next_u32(&mut self) -> u32 {
        match self {
            Sampler::Independent(s) => s.next_u32(),
            Sampler::Sobol(s) => s.next_u32(),
        }
    }

    /// A uniform number in `[0, 1)` with 24 random bits.
    #[inline(always)]
    pub fn next_f32(&mut self) -> f32 {
        match self {
            Sampler::Independent(s) => s.next_f32(),
            Sampler::Sobol(s) => s.next_f32(),
        }
    }

    /// A uniform number in `[0, 1)` with 53 random bits, for choices among many options whose
    /// probabilities are finer than `next_f32`'s grid of 2^-24.
    #[inline(always)]
    pub fn next_f64(&mut self) -> f64 {
        match self {
            Sampler::Independent(s) => s.next_f64(),
            Sampler::Sobol(s) => s.next_f64(),
        }
    }

    /// A 2D point in `[0, 1)^2` with 53 random bits a coordinate, for a choice among many
    /// cells in two dimensions (an environment map's rows and columns).
    #[inline(always)]
    pub fn next_2d_f64(&mut self) -> (f64, f64) {
        match self {
            Sampler::Independent(s) => s.next_2d_f64(),
            Sampler::Sobol(s) => s.next_2d_f64(),
        }
    }

    /// Two uniform numbers in `[0, 1)`: a 2D point.
    #[inline(always)]
    pub fn next_2d(&mut self) -> (f32, f32) {
        match self {
            Sampler::Independent(s) => s.next_2d(),
            Sampler::Sobol(s) => s.next_2d(),
        }
    }

    /// Run `work` with the [`Streams`] of this sampler's kind: the one `match` on the kind
    /// that code drawing in lanes needs, compiled for each kind.
    #[inline(always)]
    pub fn with_streams<W: WithStreams>(&self, work: W) -> W::Out {
        match self {
            Sampler::Independent(_) => work.run::<PcgLanes>(),
            Sampler::Sobol(_) => work.run::<SobolLanes>(),
        }
    }

    /// A uniform integer in `[0, n)` for `n > 0`.
    #[inline(always)]
    pub fn next_below(&mut self, n: u32) -> u32 {
        ((self.next_u32() as u64 * n as u64) >> 32) as u32
    }
}

/// Up to [`LANES`] samplers of one kind drawn side by side, lane `i` drawing as sampler `i`'s
/// own [`Sampler`] methods would: the same numbers, in lanes. Each kind's lanes are a type of
/// their own ([`PcgLanes`], [`SobolLanes`]), so that code drawing in lanes is compiled for
/// each kind without a `match` per draw (`shader::path::lanes` picks the kind once per chunk).
pub trait Streams: Copy {
    /// The streams of `samplers` (at most [`LANES`]), lane `i` from `samplers[i]`; lanes past
    /// them draw numbers that nobody reads.
    ///
    /// # Panics
    /// If a sampler is of another kind: a render's samplers all come from `camera_ray`, of
    /// its film's kind, so a mixed wave is a caller's bug, refused rather than drawn from
    /// numbers of the wrong kind. (Ruling it out by type would make the tracer and the waves
    /// generic over the sampler.)
    fn load<'a>(samplers: impl Iterator<Item = &'a Sampler>) -> Self;

    /// Lane `i`'s sampler, where it has got to.
    fn sampler(&self, i: usize) -> Sampler;

    /// [`Sampler::next_u32`] in the first `lanes` lanes.
    fn next_u32(&mut self, lanes: usize) -> [u32; LANES];

    /// [`Sampler::next_f64`] in the first `lanes` lanes.
    fn next_f64(&mut self, lanes: usize) -> [f64; LANES];

    /// [`Sampler::next_2d`] in the first `lanes` lanes: the two coordinates' arrays.
    fn next_2d(&mut self, lanes: usize) -> ([f32; LANES], [f32; LANES]);

    /// [`Sampler::next_2d_f64`] in lane `i` alone (a draw the other lanes do not make).
    fn next_2d_f64_at(&mut self, i: usize) -> (f64, f64);
}

/// Work to run with the [`Streams`] of a sampler's kind ([`Sampler::with_streams`]): a
/// generic method, which a closure cannot have.
pub trait WithStreams {
    /// What the work gives.
    type Out;

    /// Run the work with the streams type `S`.
    fn run<S: Streams>(self) -> Self::Out;
}

/// The most lanes [`Streams`] draw in.
pub const LANES: usize = 16;

/// [`Streams::load`]'s refusal of a wave of two samplers.
const MIXED: &str =
    "a wave of samples of two samplers: a render's samplers all come from its film's kind";

impl Streams for PcgLanes {
    #[inline(always)]
    fn load<'a>(samplers: impl Iterator<Item = &'a Sampler>) -> Self {
        PcgLanes::load(samplers.map(|s| match s {
            Sampler::Independent(s) => s,
            Sampler::Sobol(_) => panic!("{MIXED}"),
        }))
    }

    #[inline(always)]
    fn sampler(&self, i: usize) -> Sampler {
        Sampler::Independent(PcgLanes::sampler(self, i))
    }

    #[inline(always)]
    fn next_u32(&mut self, lanes: usize) -> [u32; LANES] {
        PcgLanes::next_u32(self, lanes)
    }

    #[inline(always)]
    fn next_f64(&mut self, lanes: usize) -> [f64; LANES] {
        PcgLanes::next_f64(self, lanes)
    }

    #[inline(always)]
    fn next_2d(&mut self, lanes: usize) -> ([f32; LANES], [f32; LANES]) {
        PcgLanes::next_2d(self, lanes)
    }

    #[inline(always)]
    fn next_2d_f64_at(&mut self, i: usize) -> (f64, f64) {
        PcgLanes::next_2d_f64_at(self, i)
    }
}

impl Streams for SobolLanes {
    #[inline(always)]
    fn load<'a>(samplers: impl Iterator<Item = &'a Sampler>) -> Self {
        SobolLanes::load(samplers.map(|s| match s {
            Sampler::Sobol(s) => s,
            Sampler::Independent(_) => panic!("{MIXED}"),
        }))
    }

    #[inline(always)]
    fn sampler(&self, i: usize) -> Sampler {
        Sampler::Sobol(SobolLanes::sampler(self, i))
    }

    #[inline(always)]
    fn next_u32(&mut self, lanes: usize) -> [u32; LANES] {
        SobolLanes::next_u32(self, lanes)
    }

    #[inline(always)]
    fn next_f64(&mut self, lanes: usize) -> [f64; LANES] {
        SobolLanes::next_f64(self, lanes)
    }

    #[inline(always)]
    fn next_2d(&mut self, lanes: usize) -> ([f32; LANES], [f32; LANES]) {
        SobolLanes::next_2d(self, lanes)
    }

    #[inline(always)]
    fn next_2d_f64_at(&mut self, i: usize) -> (f64, f64) {
        SobolLanes::next_2d_f64_at(self, i)
    }
}
