//! Image error metrics.

use crate::render::film::Image;

/// Root mean squared error over every channel of every pixel.
pub fn rmse(a: &Image, reference: &Image) -> f64 {
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(p, r)| {
            let d = (*p - *r).as_dvec3();
            d.dot(d)
        })
        .sum();
    (sum / (3 * a.pixels.len().max(1)) as f64).sqrt()
}

/// Relative MSE: the mean of `(x - r)^2 / (r^2 + 0.01)` over channels and pixels, which weighs
/// dark regions as much as bright ones.
pub fn rel_mse(a: &Image, reference: &Image) -> f64 {
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(p, r)| {
            let (p, r) = (p.as_dvec3(), r.as_dvec3());
            let d = (p - r) * (p - r) / (r * r + 0.01);
            d.element_sum()
        })
        .sum();
    sum / (3 * a.pixels.len().max(1)) as f64
}

/// FNV-1a, 64 bits: a stable hash for cache keys and image fingerprints.
pub fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
    })
}
