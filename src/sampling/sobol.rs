//! The Sobol' sampler: padded, Owen-scrambled Sobol' points (Burley, "Practical Hash-based
//! Owen Scrambling", JCGT 9(4), 2020), as pbrt-v4's `PaddedSobolSampler` uses them.
//!
//! Each draw of a sample is a dimension of its own (one per call, whatever the call draws).
//! Dimension `d` of sample `i` of a pixel takes the point of index `j` of Sobol's first two
//! dimensions (a (0,2)-sequence in base 2), where `j` is `i` shuffled by a nested uniform
//! scramble seeded by (seed, pixel, `d`), and scrambles each of its coordinates with a nested
//! uniform (Owen) scramble seeded the same way with another salt.
//!
//! - **Stratified.** The shuffle maps the first `2^m` indices onto `2^m` indices that differ
//!   only in their low `m` bits, all of them, so for a power-of-two `spp` a pixel's points of
//!   one 2D draw form a (0,m,2)-net: one point in every elementary interval of area `2^-m`
//!   (`tests`: `a_pixels_points_are_a_net`), and a 1D draw's one point in every `1/spp`.
//! - **Unbiased.** Owen scrambling makes each point uniform on `[0, 1)^2`, whatever `spp`.
//! - **Padded.** Each dimension has its own shuffle, so draws of different dimensions are not
//!   correlated; a path whose vertices draw different numbers of times stays unbiased.
//!
//! The scrambles are Laine and Karras's hash permutation ("Stratified sampling for stochastic
//! transparency", 2011) in the bit-reversed domain, with Vegdahl's constants ("Building a
//! better LK hash", 2021); the per-dimension seeds hash with Wellons's `lowbias32`.

use super::rng::{mix, to_f32, to_f64};

/// One sample's stream of Sobol' points: which sample of which pixel, and how many
/// dimensions it has drawn.
#[derive(Clone, Copy, Debug)]
pub struct Sobol {
    /// The (seed, pixel) hash every dimension's seeds derive from, 64 bits in two halves (so
    /// that two pixels share their points in every dimension with probability `2^-64`, not
    /// `2^-32`: millions of pixels would hold hundreds of such pairs).
    key: [u32; 2],
    /// The sample's index among its pixel's.
    index: u32,
    /// The next dimension.
    dim: u32,
}

/// Wellons's `lowbias32`: a bijective 32-bit mix.
#[inline(always)]
fn hash(mut x: u32) -> u32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^ (x >> 16)
}

/// The Laine-Karras permutation under `seed`: bit `k` of the result is bit `k` of `x` flipped
/// by a function of `x`'s bits below `k` (an addition, a multiplication by an odd number and
/// xors with `x` times an even number each keep that form), so in the bit-reversed domain it
/// is a nested uniform scramble.
#[inline(always)]
fn laine_karras(mut x: u32, seed: u32) -> u32 {
    x ^= x.wrapping_mul(0x3d20_adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x0552_6c56);
    x ^ x.wrapping_mul(0x53a2_2864)
}

/// The nested uniform (Owen) scramble of the binary fraction `x` (bit 31 its first digit):
/// each digit flipped by a hash of the digits before it.
#[inline(always)]
fn owen(x: u32, seed: u32) -> u32 {
    laine_karras(x.reverse_bits(), seed).reverse_bits()
}

/// Sobol's second dimension at index `j`, bit-reversed (its first digit in bit 0): the sum
/// over `j`'s set bits `k` of the direction numbers `v_k` of the primitive polynomial `x + 1`,
/// whose digit `i` is `C(k, i) mod 2`, that is (Lucas) whether `i`'s bits are among `k`'s.
/// So digit `i` is the parity of `j`'s bits at the positions `k` that are supersets of `i`: a
/// superset sum over the five bits of a position, one shift per bit.
#[inline(always)]
fn sobol_second_reversed(j: u32) -> u32 {
    let mut y = j;
    y ^= (y >> 1) & 0x5555_5555;
    y ^= (y >> 2) & 0x3333_3333;
    y ^= (y >> 4) & 0x0f0f_0f0f;
    y ^= (y >> 8) & 0x00ff_00ff;
    y ^ ((y >> 16) & 0x0000_ffff)
}

/// The seeds of dimension `dim` under `key`: the index shuffle's and the two coordinates'.
/// The dimension is spread by the golden ratio's 32 bits; the two salts are arbitrary odd
/// constants (Eiserloh's noise constants) that tell the coordinates' seeds apart.
#[inline(always)]
fn seeds(key: [u32; 2], dim: u32) -> (u32, u32, u32) {
    let s = hash(key[0] ^ hash(key[1] ^ dim.wrapping_mul(0x9e37_79b9)));
    (s, hash(s ^ 0x68e3_1da4), hash(s ^ 0xb529_7a4d))
}

/// The 1D point (32 bits of a fraction) of sample `index` in dimension `dim` under `key`: the
/// first Sobol' dimension (the van der Corput sequence: `j` reversed) of the shuffled index
/// `j`, scrambled (`owen(j.reverse_bits())`, its two reversals cancelled).
#[inline(always)]
pub fn point_1d(key: [u32; 2], index: u32, dim: u32) -> u32 {
    let (shuffle, sx, _) = seeds(key, dim);
    let j = owen(index, shuffle);
    laine_karras(j, sx).reverse_bits()
}

/// The 2D point of sample `index` in dimension `dim` under `key`: Sobol's first two
/// dimensions of the shuffled index, each scrambled.
#[inline(always)]
pub fn point_2d(key: [u32; 2], index: u32, dim: u32) -> (u32, u32) {
    let (shuffle, sx, sy) = seeds(key, dim);
    let j = owen(index, shuffle);
    let x = laine_karras(j, sx).reverse_bits();
    (x, laine_karras(sobol_second_reversed(j), sy).reverse_bits())
}

/// 21 more bits for a 53-bit fraction after the 32 of `bits`: a hash of them and the
/// dimension's seed (below the point's 32 digits, the scramble would draw them at random too).
#[inline(always)]
fn low_bits(bits: u32, key: [u32; 2], dim: u32) -> u32 {
    hash(bits ^ seeds(key, dim).2) & ((1 << 21) - 1)
}

// The draws are not inlined, so that `Sampler`'s, which `match` on the sampler, stay small
// enough to inline for the independent sampler.
impl Sobol {
    /// The points of sample `sample` of pixel `pixel` (row-major index) under `seed`.
    pub fn new(seed: u64, pixel: u64, sample: u64) -> Self {
        Sobol {
            key: {
                let k = mix(mix(seed) ^ pixel);
                [k as u32, (k >> 32) as u32]
            },
            index: sample as u32,
            dim: 0,
        }
    }

    /// Skip `dims` dimensions, as that many draws would.
    pub fn skip(&mut self, dims: u32) {
        self.dim = self.dim.wrapping_add(dims);
    }

    /// The next dimension's 1D point, 32 bits.
    #[inline(never)]
    pub fn next_u32(&mut self) -> u32 {
        let x = point_1d(self.key, self.index, self.dim);
        self.dim = self.dim.wrapping_add(1);
        x
    }

    /// The next dimension's 1D point in `[0, 1)`, 24 bits.
    #[inline(never)]
    pub fn next_f32(&mut self) -> f32 {
        to_f32(self.next_u32())
    }

    /// The next dimension's 1D point in `[0, 1)`, 53 bits.
    #[inline(never)]
    pub fn next_f64(&mut self) -> f64 {
        let (key, dim) = (self.key, self.dim);
        let x = self.next_u32();
        to_f64(x, low_bits(x, key, dim) << 11)
    }

    /// The next dimension's 2D point in `[0, 1)^2`, 53 bits a coordinate: the 32 of the point,
    /// then 21 hashed, `x`'s as [`Sobol::next_f64`]'s, `y`'s from `y` and `x`'s.
    #[inline(never)]
    pub fn next_2d_f64(&mut self) -> (f64, f64) {
        let (key, dim) = (self.key, self.dim);
        let (x, y) = point_2d(key, self.index, dim);
        self.dim = self.dim.wrapping_add(1);
        let low = low_bits(x, key, dim);
        (
            to_f64(x, low << 11),
            to_f64(y, low_bits(y ^ low, key, dim) << 11),
        )
    }

    /// The next dimension's 2D point in `[0, 1)^2`.
    #[inline(never)]
    pub fn next_2d(&mut self) -> (f32, f32) {
        let (x, y) = point_2d(self.key, self.index, self.dim);
        self.dim = self.dim.wrapping_add(1);
        (to_f32(x), to_f32(y))
    }
}

/// Up to [`SobolLanes::MAX`] Sobol' streams side by side, lane `i` drawing as its own
/// [`Sobol`] would: loops over fixed arrays without branches, turned into SIMD instructions
/// where they are inlined.
#[derive(Clone, Copy)]
pub struct SobolLanes {
    /// Each lane's key, its two halves in two arrays.
    key: [[u32; SobolLanes::MAX]; 2],
    index: [u32; SobolLanes::MAX],
    dim: [u32; SobolLanes::MAX],
}

impl SobolLanes {
    /// The most lanes.
    pub const MAX: usize = 16;

    /// The streams of `samplers` (at most [`SobolLanes::MAX`]); lanes past them draw numbers
    /// that nobody reads.
    #[inline(always)]
    pub fn load<'a>(samplers: impl Iterator<Item = &'a Sobol>) -> SobolLanes {
        let mut s = SobolLanes {
            key: [[0; Self::MAX]; 2],
            index: [0; Self::MAX],
            dim: [0; Self::MAX],
        };
        for (i, sampler) in samplers.take(Self::MAX).enumerate() {
            (s.key[0][i], s.key[1][i]) = (sampler.key[0], sampler.key[1]);
            (s.index[i], s.dim[i]) = (sampler.index, sampler.dim);
        }
        s
    }

    /// Lane `i`'s stream, where it has got to.
    #[inline(always)]
    pub fn sampler(&self, i: usize) -> Sobol {
        Sobol {
            key: [self.key[0][i], self.key[1][i]],
            index: self.index[i],
            dim: self.dim[i],
        }
    }

    /// Each of the first `lanes` lanes' (key, index, dimension), its dimension then moved on.
    #[inline(always)]
    fn draw(&mut self, lanes: usize) -> impl Iterator<Item = ([u32; 2], u32, u32)> + '_ {
        let keys = self.key[0].iter().zip(&self.key[1]);
        let lanes_of = keys.zip(&self.index).zip(&mut self.dim).take(lanes);
        lanes_of.map(|(((&k0, &k1), &index), dim)| {
            let d = *dim;
            *dim = d.wrapping_add(1);
            ([k0, k1], index, d)
        })
    }

    /// [`Sobol::next_u32`] in the first `lanes` lanes.
    #[inline(always)]
    pub fn next_u32(&mut self, lanes: usize) -> [u32; Self::MAX] {
        let mut out = [0; Self::MAX];
        for (out, (key, index, dim)) in out.iter_mut().zip(self.draw(lanes)) {
            *out = point_1d(key, index, dim);
        }
        out
    }

    /// [`Sobol::next_f64`] in the first `lanes` lanes. `to_f64(x, y << 11)` is
    /// `(x 2^21 + y) 2^-53` for `y < 2^21`, a number of 53 bits, so it is `x 2^-32 + y 2^-53`
    /// exactly: two conversions of 32-bit numbers, which AVX-512F has in lanes.
    #[inline(always)]
    pub fn next_f64(&mut self, lanes: usize) -> [f64; Self::MAX] {
        let mut out = [0.0; Self::MAX];
        for (out, (key, index, dim)) in out.iter_mut().zip(self.draw(lanes)) {
            let x = point_1d(key, index, dim);
            let y = low_bits(x, key, dim);
            *out = x as f64 * (1.0 / (1u64 << 32) as f64) + y as f64 * (1.0 / (1u64 << 53) as f64);
        }
        out
    }

    /// [`Sobol::next_2d_f64`] in lane `i` alone.
    #[inline(always)]
    pub fn next_2d_f64_at(&mut self, i: usize) -> (f64, f64) {
        let mut s = self.sampler(i);
        let v = s.next_2d_f64();
        self.dim[i] = s.dim;
        v
    }

    /// [`Sobol::next_2d`] in the first `lanes` lanes: the two coordinates' arrays.
    #[inline(always)]
    pub fn next_2d(&mut self, lanes: usize) -> ([f32; Self::MAX], [f32; Self::MAX]) {
        let (mut x, mut y) = ([0.0; Self::MAX], [0.0; Self::MAX]);
        for ((x, y), (key, index, dim)) in x.iter_mut().zip(&mut y).zip(self.draw(lanes)) {
            let (a, b) = point_2d(key, index, dim);
            (*x, *y) = (to_f32(a), to_f32(b));
        }
        (x, y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `laine_karras` keeps the nested form: flipping bit `k` of the input changes no bit
    /// below `k` of the output, and it is a bijection on every low-bit prefix.
    #[test]
    fn laine_karras_flips_each_bit_by_the_bits_below() {
        for seed in [0u32, 1, 0xdead_beef, 0x8000_0001] {
            for x in [0u32, 1, 0x1234_5678, u32::MAX, 0x8000_0000] {
                for k in 0..32 {
                    let d = laine_karras(x, seed) ^ laine_karras(x ^ (1 << k), seed);
                    assert_eq!(
                        d & ((1u32 << k) - 1),
                        0,
                        "seed {seed:#x}, x {x:#x}, bit {k}"
                    );
                    assert_ne!(d & (1 << k), 0, "bit {k} must still flip");
                }
            }
            let mut seen = [false; 256];
            for x in 0..256u32 {
                seen[(laine_karras(x, seed) & 0xff) as usize] = true;
            }
            assert!(seen.iter().all(|&s| s));
        }
    }

    /// Sobol's second dimension: its first points by hand (0, 1/2, 3/4, 1/4, 5/8, 1/8, ...),
    /// and every index's against the direction numbers summed bit by bit.
    #[test]
    fn sobol_second_dimension_gives_the_known_points() {
        let want = [0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875];
        for (j, w) in want.iter().enumerate() {
            let x = sobol_second_reversed(j as u32).reverse_bits();
            assert_eq!(x as f64 / 2f64.powi(32), *w, "index {j}");
        }
        for j in (0..1u32 << 16).chain([u32::MAX, 0x8000_0000, 0xdead_beef, 0x1357_9bdf]) {
            let (mut v, mut x) = (1u32 << 31, 0u32);
            for k in 0..32 {
                if (j >> k) & 1 == 1 {
                    x ^= v;
                }
                v ^= v >> 1;
            }
            assert_eq!(sobol_second_reversed(j).reverse_bits(), x, "index {j:#x}");
        }
    }

    /// A pixel's `2^m` points of one 2D draw: one in every elementary interval of area `2^-m`
    /// (every split of the `m` digits between the two axes), and its 1D draws one in every
    /// `2^-m`, for several pixels and dimensions.
    #[test]
    fn a_pixels_points_are_a_net() {
        for m in [0u32, 1, 4, 6, 9] {
            let n = 1u32 << m;
            for (pixel, dim) in [(0u64, 0u32), (17, 3), (123_456, 40)] {
                let points: Vec<(u32, u32)> = (0..n)
                    .map(|i| {
                        let mut s = Sobol::new(5, pixel, i as u64);
                        s.dim = dim;
                        let p = point_2d(s.key, i, dim);
                        assert_eq!(p.0, point_1d(s.key, i, dim), "the 1D draw is the 2D's x");
                        // The 53-bit draw's first 32 bits are the point's.
                        let (x, y) = Sobol { dim, ..s }.next_2d_f64();
                        let top = |v: f64| (v * 2f64.powi(32)) as u32;
                        assert_eq!((top(x), top(y)), p, "the 53-bit draw");
                        p
                    })
                    .collect();
                for a in 0..=m {
                    let b = m - a;
                    let mut seen = vec![false; n as usize];
                    for &(x, y) in &points {
                        let cx = if a == 0 { 0 } else { x >> (32 - a) };
                        let cy = if b == 0 { 0 } else { y >> (32 - b) };
                        let cell = ((cx << b) | cy) as usize;
                        assert!(
                            !seen[cell],
                            "m {m}, pixel {pixel}, dim {dim}: two points in cell {a}x{b}"
                        );
                        seen[cell] = true;
                    }
                }
            }
        }
    }

    /// Dimensions are padded, not aligned: a pixel's 64 samples' numbers in dimension `d` and
    /// `d + 1` pair up as independent numbers would, filling about `1 - 1/e` of an 8 x 8 grid
    /// (a set stratified jointly, as dimensions sharing their shuffle would be, fills all 64
    /// cells or a diagonal of 8). And pixels draw different points.
    #[test]
    fn dimensions_and_pixels_are_independent() {
        let (mut filled, mut cells) = (0, 0);
        for pixel in 0..40u64 {
            for d in [0u32, 5, 31] {
                let mut seen = [false; 64];
                for i in 0..64u32 {
                    let s = Sobol::new(9, pixel, i as u64);
                    let (a, b) = (point_1d(s.key, i, d), point_1d(s.key, i, d + 1));
                    assert_ne!(a, b, "pixel {pixel}, dims {d} and {}", d + 1);
                    seen[((a >> 29) * 8 + (b >> 29)) as usize] = true;
                }
                filled += seen.iter().filter(|&&x| x).count();
                cells += 64;
            }
        }
        let share = filled as f64 / cells as f64;
        // 120 sets of 64: the share's standard deviation is about 0.003 around 0.634.
        assert!(
            (share - 0.634).abs() < 0.03,
            "share of cells filled {share}"
        );
        let points: std::collections::HashSet<(u32, u32)> = (0..10_000u64)
            .map(|pixel| {
                let s = Sobol::new(9, pixel, 0);
                point_2d(s.key, 0, 0)
            })
            .collect();
        assert_eq!(points.len(), 10_000, "two pixels drew the same point");
        // Keys that differ in the same bit of both halves (equal if the halves were xored)
        // draw apart.
        let (a, b) = ([0x1234_5678u32, 0x9abc_def0], [0x1234_5679u32, 0x9abc_def1]);
        assert!((0..8).any(|d| point_2d(a, 0, d) != point_2d(b, 0, d)));
        // Keys that share a half still draw apart: both halves seed every dimension.
        for half in [0, 1] {
            let (mut a, mut b) = ([0x1234_5678, 0x9abc_def0], [0x1234_5678, 0x9abc_def0]);
            b[half] ^= 1;
            assert!(
                (0..8).any(|d| point_2d(a, 0, d) != point_2d(b, 0, d)),
                "half {half}"
            );
            a[1 - half] = 7;
            b[1 - half] = 7;
            assert!((0..8).any(|d| point_1d(a, 3, d) != point_1d(b, 3, d)));
        }
    }

    /// `SobolLanes` draws each lane's own numbers.
    #[test]
    fn lanes_draw_each_streams_numbers() {
        for lanes in [4, 8, 16] {
            let own: Vec<Sobol> = (0..lanes).map(|k| Sobol::new(7, k, 3 * k)).collect();
            let mut streams = SobolLanes::load(own.iter());
            let mut own = own;
            for _ in 0..4 {
                let u = streams.next_u32(lanes as usize);
                let (x, y) = streams.next_2d(lanes as usize);
                let w = streams.next_f64(lanes as usize);
                for (i, s) in own.iter_mut().enumerate() {
                    assert_eq!(u[i], s.next_u32());
                    let (a, b) = s.next_2d();
                    assert_eq!((x[i].to_bits(), y[i].to_bits()), (a.to_bits(), b.to_bits()));
                    assert_eq!(w[i].to_bits(), s.next_f64().to_bits());
                }
            }
            let last = lanes as usize - 1;
            let (a, b) = streams.next_2d_f64_at(last);
            let mut copy = own[last];
            let (c, d) = own[last].next_2d_f64();
            assert_eq!((a.to_bits(), b.to_bits()), (c.to_bits(), d.to_bits()));
            // Its `x` is the 1D draw's of the same dimension.
            assert_eq!(c.to_bits(), copy.next_f64().to_bits());
            for (i, s) in own.iter().enumerate() {
                assert_eq!(streams.sampler(i).dim, s.dim);
            }
        }
    }
}
