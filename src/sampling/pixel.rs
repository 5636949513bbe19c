//! Where inside a pixel each sample goes.

use super::Sampler;

/// The image-plane offset in `[0, 1)^2` of sample `i` of `spp` inside a pixel.
///
/// One sample goes through the pixel centre. With more, under the Sobol' sampler each sample's
/// offset is its first 2D point (stratified over the pixel's samples already); otherwise a
/// square count `m^2` jitters one sample in each cell of an `m x m` grid, and any other count
/// uses Latin-hypercube (n-rooks) strata, one row and one column of an `spp x spp` grid per
/// sample, with the column order shuffled per pixel by `perm_seed` so the strata stay
/// independent.
///
/// # Panics
/// If `i` is not a sample of the pixel (`i >= spp`): a caller's range bug, refused here with
/// its figures rather than left to the permutation, whose cycle-walking loop never ends for
/// some indices out of range.
#[inline]
pub fn pixel_sample(i: u32, spp: u32, perm_seed: u64, rng: &mut Sampler) -> (f32, f32) {
    assert!(
        i < spp,
        "sample index {i} is out of range: a pixel has the samples 0..{spp}"
    );
    if spp == 1 {
        return (0.5, 0.5);
    }
    let (jx, jy) = rng.next_2d();
    if let Sampler::Sobol(_) = rng {
        // A pixel's Sobol' points of one 2D draw are stratified already: a (0,m,2)-net for
        // `2^m` samples, finer than any grid.
        return (jx, jy);
    }
    let m = (spp as f64).sqrt() as u32;
    if m * m == spp {
        let (cx, cy) = (i % m, i / m);
        return ((cx as f32 + jx) / m as f32, (cy as f32 + jy) / m as f32);
    }
    let col = permute(i, spp, perm_seed);
    ((col as f32 + jx) / spp as f32, (i as f32 + jy) / spp as f32)
}

/// A pseudo-random permutation of `0..n` evaluated at `i` (Kensler's hashed permutation,
/// "Correlated Multi-Jittered Sampling", 2013), so no table is stored per pixel.
///
/// The loop walks the cycle of `i` under a bijection of `0..=w` until it lands below `n`; for
/// `i < n` that ends within the cycle, so within `w + 1` steps, but an `i` in `n..=w` can sit on
/// a cycle that never enters `0..n`, so such an index is refused. The walk is bounded by the
/// cycle's longest length: a step that is not a bijection fails at once instead of looping.
fn permute(mut i: u32, n: u32, seed: u64) -> u32 {
    assert!(i < n, "permutation index {i} is out of range 0..{n}");
    let p = seed as u32;
    let mut w = n - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    for _ in 0..=w {
        i ^= p;
        i = i.wrapping_mul(0xe170893d);
        i ^= p >> 16;
        i ^= (i & w) >> 4;
        i ^= p >> 8;
        i = i.wrapping_mul(0x0929eb3f);
        i ^= p >> 23;
        i ^= (i & w) >> 1;
        i = i.wrapping_mul(1 | p >> 27);
        i = i.wrapping_mul(0x6935fa69);
        i ^= (i & w) >> 11;
        i = i.wrapping_mul(0x74dcb303);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0x9e501cc3);
        i ^= (i & w) >> 2;
        i = i.wrapping_mul(0xc860a3df);
        i &= w;
        i ^= i >> 5;
        if i < n {
            return (i + p) % n;
        }
    }
    panic!(
        "the permutation of 0..{n} did not return below {n} within {} steps",
        w as u64 + 1
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn permute_is_a_permutation() {
        for n in [2u32, 3, 5, 7, 10, 33] {
            for seed in [0u64, 1, 12345] {
                let mut seen: Vec<u32> = (0..n).map(|i| permute(i, n, seed)).collect();
                seen.sort();
                assert_eq!(seen, (0..n).collect::<Vec<_>>(), "n={n} seed={seed}");
            }
        }
    }

    /// An index past the end is refused at once: without the check, `permute(3, 3, 0)` never
    /// returns (the bijection of 0..=3 maps 3 to itself, so the walk never goes below 3).
    #[test]
    #[should_panic(expected = "permutation index 3 is out of range 0..3")]
    fn permute_refuses_an_index_out_of_range() {
        permute(3, 3, 0);
    }
}
