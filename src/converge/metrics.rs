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

pub use crate::render::pass::fnv1a;

/// Largest absolute difference of any channel of any pixel.
pub fn max_abs_error(a: &Image, reference: &Image) -> f64 {
    a.pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(p, r)| (*p - *r).abs().max_element() as f64)
        .fold(0.0, f64::max)
}

/// NVIDIA's FLIP between two images (LDR-FLIP on their 8-bit sRGB encodings, at FLIP's default
/// 67 pixels per degree: a 0.7 m wide monitor of 3840 pixels seen from 0.7 m).
#[derive(Clone, Debug)]
pub struct Flip {
    /// Mean FLIP error over the pixels, in [0, 1].
    pub mean: f64,
    /// FLIP error per pixel, row-major, in [0, 1].
    pub map: Vec<f32>,
    /// The map through FLIP's magma colour map (black: no perceived difference), RGB8.
    pub heatmap: image::RgbImage,
}

/// FLIP between `test` and `reference`, both 8-bit sRGB images of one size.
pub fn flip_rgb8(test: &image::RgbImage, reference: &image::RgbImage) -> Flip {
    let (w, h) = test.dimensions();
    let t = nv_flip::FlipImageRgb8::with_data(w, h, test.as_raw());
    let r = nv_flip::FlipImageRgb8::with_data(w, h, reference.as_raw());
    let err = nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let mean = nv_flip::FlipPool::from_image(&err).mean() as f64;
    let map = err.to_vec();
    let lut = nv_flip::magma_lut();
    let colored = err.apply_color_lut(&lut);
    let heatmap =
        image::RgbImage::from_raw(w, h, colored.to_vec()).expect("FLIP's map has the size");
    Flip { mean, map, heatmap }
}

/// FLIP between two linear images of one size, through their sRGB encodings.
pub fn flip(test: &Image, reference: &Image) -> Flip {
    let enc = |i: &Image| crate::render::output::to_rgb8(i, crate::render::output::Transfer::Srgb);
    flip_rgb8(&enc(test), &enc(reference))
}

/// Over images of one scene rendered with independent seeds: the variance (mean over pixels and
/// channels of the unbiased per-pixel variance across the images) and the MSE of their
/// per-pixel mean against `reference`.
pub fn variance_and_mse_of_mean(images: &[Image], reference: &Image) -> (f64, f64) {
    let k = images.len().max(1) as f64;
    let (mut var, mut mse) = (0.0f64, 0.0f64);
    for (i, r) in reference.pixels.iter().enumerate() {
        let r = r.as_dvec3();
        let mean = images
            .iter()
            .map(|im| im.pixels[i].as_dvec3())
            .sum::<glam::DVec3>()
            / k;
        if images.len() > 1 {
            let ss: glam::DVec3 = images
                .iter()
                .map(|im| {
                    let d = im.pixels[i].as_dvec3() - mean;
                    d * d
                })
                .sum();
            var += (ss / (k - 1.0)).element_sum();
        }
        let d = mean - r;
        mse += d.dot(d);
    }
    let n = (3 * reference.pixels.len().max(1)) as f64;
    (var / n, mse / n)
}

/// A rung's error split into its parts ([`bias_and_variance`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decomposition {
    /// The mean over pixels and channels of the unbiased per-pixel variance across the seeds.
    pub variance: f64,
    /// The squared bias, estimated without bias: can dip below zero by noise where it is small.
    pub bias2: f64,
}

/// Squared bias and variance of a rung from `k` images of independent seeds, against a
/// reference whose own noise variance per pixel and channel is `reference_noise`.
///
/// For a pixel value `x_i = mu + b + e_i` (seed noise of variance `s^2`) and a reference
/// `r = mu + e_r` (noise variance `v_r`), the mean of the seeds `m` has
/// `E[(m - r)^2] = b^2 + s^2 / k + v_r`, and the seeds' sample variance estimates `s^2` without
/// bias. So `bias2 = MSE(m, r) - variance / k - v_r`, averaged over pixels and channels.
pub fn bias_and_variance(
    images: &[Image],
    reference: &Image,
    reference_noise: f64,
) -> Decomposition {
    let (variance, mse_of_mean) = variance_and_mse_of_mean(images, reference);
    let k = images.len().max(1) as f64;
    Decomposition {
        variance,
        bias2: mse_of_mean - variance / k - reference_noise,
    }
}

/// The noise variance per pixel and channel of the pooled mean of two independent renders of
/// one scene, `a` of `na` samples per pixel and `b` of `nb`, each over the whole pixel.
///
/// With a per-sample variance `s^2`, `a - b` has variance `s^2 (1/na + 1/nb)`, which their mean
/// squared difference estimates; the pooled mean of `na + nb` samples has `s^2 / (na + nb)`.
pub fn pooled_noise(a: &Image, na: u64, b: &Image, nb: u64) -> f64 {
    let (na, nb) = (na.max(1) as f64, nb.max(1) as f64);
    rmse(a, b).powi(2) / ((1.0 / na + 1.0 / nb) * (na + nb))
}

/// Per-pixel relative squared error `(x - r)^2 / (r^2 + 0.01)`, averaged over channels.
pub fn rel_se_map(a: &Image, reference: &Image) -> Vec<f32> {
    a.pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(p, r)| {
            let (p, r) = (p.as_dvec3(), r.as_dvec3());
            ((p - r) * (p - r) / (r * r + 0.01)).element_sum() as f32 / 3.0
        })
        .collect()
}

/// Per-pixel squared error `(x - r)^2`, averaged over channels.
pub fn se_map(a: &Image, reference: &Image) -> Vec<f32> {
    a.pixels
        .iter()
        .zip(&reference.pixels)
        .map(|(p, r)| {
            let d = p.as_dvec3() - r.as_dvec3();
            (d * d).element_sum() as f32 / 3.0
        })
        .collect()
}
