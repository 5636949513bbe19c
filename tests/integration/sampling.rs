//! Sampler invariants (proptest) and statistical moments with stated tolerances.

use glam::Vec3A;
use proptest::prelude::*;
use rtis::geometry::Frame;
use rtis::sampling::{Sampler, hemisphere};

fn unit() -> impl Strategy<Value = Vec3A> {
    prop_oneof![
        (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
            .prop_filter("non-degenerate", |(x, y, z)| x * x + y * y + z * z > 1e-6)
            .prop_map(|(x, y, z)| Vec3A::new(x, y, z).normalize()),
        // The directions where a fixed-axis cross product would degenerate.
        Just(Vec3A::X),
        Just(Vec3A::Y),
        Just(Vec3A::Z),
        Just(-Vec3A::Z),
        Just(Vec3A::new(0.0, 0.0, -0.0).normalize_or(Vec3A::NEG_Z)),
        Just(Vec3A::new(1e-7, 0.0, -1.0).normalize()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(5000))]

    /// The frame is orthonormal and right-handed for every unit normal.
    #[test]
    fn frame_is_orthonormal(n in unit()) {
        let f = Frame::from_normal(n);
        for v in [f.s, f.t, f.n] {
            prop_assert!((v.length() - 1.0).abs() < 1e-5);
        }
        prop_assert!(f.s.dot(f.t).abs() < 1e-5 && f.s.dot(f.n).abs() < 1e-5 && f.t.dot(f.n).abs() < 1e-5);
        prop_assert!((f.s.cross(f.t) - f.n).length() < 1e-5);
        let v = Vec3A::new(0.3, -0.5, 0.8);
        prop_assert!((f.to_local(f.to_world(v)) - v).length() < 1e-5);
    }

    /// Uniform and cosine samples are unit length and in the upper hemisphere of any normal.
    #[test]
    fn hemisphere_samples_are_unit_and_above(n in unit(), u1 in 0.0f32..1.0, u2 in 0.0f32..1.0) {
        let f = Frame::from_normal(n);
        for local in [hemisphere::uniform(u1, u2), hemisphere::cosine(u1, u2)] {
            let w = f.to_world(local);
            prop_assert!((w.length() - 1.0).abs() < 1e-5, "length {}", w.length());
            prop_assert!(w.dot(n) >= -1e-6, "below: {}", w.dot(n));
        }
    }

    /// The sampler gives numbers in [0, 1).
    #[test]
    fn sampler_range(seed in any::<u64>(), pixel in any::<u64>(), sample in any::<u64>()) {
        let mut s = Sampler::new(seed, pixel, sample);
        for _ in 0..64 {
            let u = s.next_f32();
            prop_assert!((0.0..1.0).contains(&u));
        }
    }
}

/// E[cos] = 1/2 for uniform (variance 1/12) and 2/3 for cosine sampling (E[cos^2] = 1/2,
/// variance 1/18). With N = 10^6 samples, 5 standard deviations are 1.5e-3 and 1.2e-3.
#[test]
fn mean_cosine_matches_theory() {
    let n = 1_000_000;
    let mut s = Sampler::new(1, 2, 3);
    let (mut su, mut sc) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let (a, b) = s.next_2d();
        su += hemisphere::uniform(a, b).z as f64;
        let (a, b) = s.next_2d();
        sc += hemisphere::cosine(a, b).z as f64;
    }
    let (mu, mc) = (su / n as f64, sc / n as f64);
    assert!(
        (mu - 0.5).abs() < 5.0 * (1.0f64 / 12.0 / n as f64).sqrt(),
        "uniform mean cos {mu}"
    );
    assert!(
        (mc - 2.0 / 3.0).abs() < 5.0 * (1.0f64 / 18.0 / n as f64).sqrt(),
        "cosine mean cos {mc}"
    );
}

/// The uniform warp's azimuth is uniform too: each quadrant gets a quarter of the samples
/// (binomial standard deviation sqrt(N p (1-p)); tolerance 5 of them).
#[test]
fn uniform_azimuth_is_uniform() {
    let n = 400_000;
    let mut s = Sampler::new(9, 9, 9);
    let mut q = [0u32; 4];
    for _ in 0..n {
        let (a, b) = s.next_2d();
        let w = hemisphere::uniform(a, b);
        q[((w.x < 0.0) as usize) * 2 + (w.y < 0.0) as usize] += 1;
    }
    let sd = (n as f64 * 0.25 * 0.75).sqrt();
    for c in q {
        assert!((c as f64 - n as f64 / 4.0).abs() < 5.0 * sd, "{q:?}");
    }
}

/// Distinct sample indices (and pixels, and seeds) draw distinct streams: the first numbers of
/// 4096 streams never repeat, and the same triple always gives the same stream.
#[test]
fn distinct_samples_draw_distinct_streams() {
    let mut seen = std::collections::HashSet::new();
    for seed in [0u64, 1] {
        for pixel in [0u64, 1, 1000] {
            for sample in 0..(4096 / 6) as u64 {
                let mut s = Sampler::new(seed, pixel, sample);
                let first = (
                    s.next_f32().to_bits(),
                    s.next_f32().to_bits(),
                    s.next_f32().to_bits(),
                );
                assert!(
                    seen.insert(first),
                    "seed {seed} pixel {pixel} sample {sample} repeats"
                );
            }
        }
    }
    let (mut a, mut b) = (Sampler::new(7, 8, 9), Sampler::new(7, 8, 9));
    assert_eq!(a.next_f32(), b.next_f32());
}

/// Pixel samples are stratified: with 4 samples one falls in each quadrant of the pixel, with
/// 3 (n-rooks) each third of the pixel holds one sample in x and one in y.
#[test]
fn pixel_samples_fill_their_strata() {
    use rtis::sampling::pixel_sample;
    for seed in 0..20u64 {
        let mut s = Sampler::new(seed, 0, 0);
        let mut quadrants: Vec<(u32, u32)> = (0..4)
            .map(|i| {
                let (x, y) = pixel_sample(i, 4, seed, &mut s);
                assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                ((x * 2.0) as u32, (y * 2.0) as u32)
            })
            .collect();
        quadrants.sort();
        assert_eq!(quadrants, vec![(0, 0), (0, 1), (1, 0), (1, 1)]);
        let (mut xs, mut ys): (Vec<u32>, Vec<u32>) = (0..3)
            .map(|i| {
                let (x, y) = pixel_sample(i, 3, seed, &mut s);
                assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
                ((x * 3.0) as u32, (y * 3.0) as u32)
            })
            .unzip();
        xs.sort();
        ys.sort();
        assert_eq!((xs, ys), (vec![0, 1, 2], vec![0, 1, 2]));
    }
}

/// The stream seeds' mix is a good hash: flipping one input bit flips half the output bits on
/// average (strict avalanche: 32 of 64; 64 x 200 flips, mean within 1 of 32).
#[test]
fn seed_mix_avalanches() {
    use rtis::sampling::mix;
    let mut s = Sampler::new(3, 4, 5);
    let (mut flips, mut n) = (0u64, 0u64);
    for _ in 0..200 {
        let x = ((s.next_below(u32::MAX) as u64) << 32) | s.next_below(u32::MAX) as u64;
        for bit in 0..64 {
            flips += (mix(x) ^ mix(x ^ (1 << bit))).count_ones() as u64;
            n += 1;
        }
    }
    let mean = flips as f64 / n as f64;
    assert!((mean - 32.0).abs() < 1.0, "mean flipped bits {mean}");
}

/// `next_below(n)` is uniform on 0..n: chi-squared over 7 cells, 70000 draws, below the 99.9%
/// point of chi^2 with 6 degrees of freedom (22.46).
#[test]
fn next_below_is_uniform() {
    let mut s = Sampler::new(11, 0, 0);
    let mut counts = [0f64; 7];
    for _ in 0..70_000 {
        let k = s.next_below(7);
        assert!(k < 7);
        counts[k as usize] += 1.0;
    }
    let chi2: f64 = counts
        .iter()
        .map(|c| (c - 10_000.0).powi(2) / 10_000.0)
        .sum();
    assert!(chi2 < 22.46, "chi2 {chi2}: {counts:?}");
}
