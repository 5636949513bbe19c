//! Pixel filters by filter importance sampling: each camera sample's position is drawn from the
//! filter's own distribution and weighted 1 (Ernst et al., "Filter Importance Sampling", 2006;
//! pbrt-v4's `FilterSampler`), so a pixel stays the plain mean of its samples: exact sums,
//! passes and progressive rounds hold as with the box.
//!
//! The filters are separable, `f(x, y) = f(x) f(y)`, and each axis is warped by the inverse of
//! its profile's cumulative distribution, so stratified positions stay stratified.

use super::erf_inv;
use std::f64::consts::SQRT_2;

/// The pixel filter of a film.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum PixelFilter {
    /// Each sample inside its pixel, uniformly (the course's, and rtis's default).
    #[default]
    Box,
    /// A Gaussian of standard deviation `stddev` pixels truncated at `4 stddev`, as Mitsuba 3's
    /// `gaussian` (which also subtracts its value at the radius, `exp(-8)`, 0.03% of its peak:
    /// rtis does not).
    Gaussian {
        /// Standard deviation in pixels (Mitsuba's default 0.5).
        stddev: f32,
    },
}

impl PixelFilter {
    /// Where in the pixel (`[0, 1)^2` for the box; around the centre `(1/2, 1/2)` for the
    /// others) the sample of stratified position `(dx, dy)` goes: each axis warped by the
    /// inverse of the profile's cumulative distribution. The box keeps `(dx, dy)`, bit for bit.
    #[inline]
    pub fn place(&self, (dx, dy): (f32, f32)) -> (f32, f32) {
        match *self {
            PixelFilter::Box => (dx, dy),
            PixelFilter::Gaussian { stddev } => {
                let warp = |u: f32| {
                    // The truncated normal's inverse CDF: x = s sqrt(2) erfinv((2u - 1) erf(r / (s sqrt 2))).
                    let s = stddev as f64;
                    let e = libm::erf(4.0 / SQRT_2);
                    (0.5 + s * SQRT_2 * erf_inv((2.0 * u as f64 - 1.0) * e)) as f32
                };
                (warp(dx), warp(dy))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Gaussian's warp puts the median at the centre, is odd about it, keeps within the
    /// radius, and puts 68.27% of samples within one standard deviation (the truncation at 4
    /// sigma moves it by 6e-5); the box keeps its positions.
    #[test]
    fn gaussian_warp_follows_its_profile() {
        let f = PixelFilter::Gaussian { stddev: 0.5 };
        assert_eq!(f.place((0.5, 0.5)), (0.5, 0.5));
        for u in [0.1f32, 0.3, 0.45] {
            let (a, b) = (f.place((u, u)).0, f.place((1.0 - u, 1.0 - u)).0);
            assert!((a - 0.5 + b - 0.5).abs() < 1e-5, "{a} {b}");
        }
        let (lo, hi) = (f.place((0.0, 0.0)).0, f.place((0.999_999_9, 0.0)).0);
        assert!(lo >= 0.5 - 2.0 && hi <= 0.5 + 2.0, "{lo} {hi}");
        // The share within one standard deviation: (1 - p) / 2 maps to -s.
        let p = libm::erf(1.0 / SQRT_2) / libm::erf(4.0 / SQRT_2);
        let x = f.place((((1.0 - p) / 2.0) as f32, 0.0)).0;
        assert!((x - 0.0).abs() < 1e-5, "{x}");
        assert_eq!(PixelFilter::Box.place((0.25, 0.75)), (0.25, 0.75));
    }
}
