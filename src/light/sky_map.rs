//! An environment map: a latitude-longitude image of the radiance arriving from every
//! direction, looked up bilinearly and sampled in proportion to its luminance.
//!
//! The mapping is Mitsuba 3's `envmap`, so that the same image lights a scene the same way:
//! `u = atan2(x, -z) / (2 pi)` (wrapped to [0, 1)) and `v = acos(y) / pi` of a direction
//! `(x, y, z)` in the map's frame (`y` up). Column `i` of a `w`-wide image sits at
//! `u = (i + 1/2) / w`, and `u` wraps around; row `j` of an `h`-high image sits at
//! `theta = pi j / (h - 1)`: the first row is the zenith, the last the nadir (an image one row
//! high is the same at every `theta`). Between them radiance is interpolated bilinearly. An
//! image that is not twice as wide as high still spans 360 by 180 degrees, stretched.
//!
//! Sampling: the cells between neighbouring columns and rows are drawn from a piecewise-
//! constant [`Distribution2D`], each cell weighted by the mean luminance of its four corners
//! times its solid angle (`(2 pi / w) (cos theta_j - cos theta_{j+1})`), and a point uniform in
//! `(u, v)` within the cell. The mean of the corners is the integral of the bilinear luminance
//! over the cell in `(u, v)`, and it is positive wherever the radiance is anywhere in the cell,
//! so light sampling alone is unbiased. The density per solid angle is
//! `p(u, v) / (2 pi^2 sin(theta))` (pbrt-v4's `ImageInfiniteLight`, with the sin(theta) of the
//! sphere's area element).

use crate::raster::Raster;
use crate::sampling::Distribution2D;
use glam::Vec3A;
use std::f64::consts::PI;

/// Luminance of linear RGB with Rec. 709 primaries (Mitsuba 3's `luminance`).
#[inline]
pub fn luminance(c: [f32; 3]) -> f64 {
    0.212_671 * c[0] as f64 + 0.715_160 * c[1] as f64 + 0.072_169 * c[2] as f64
}

/// A latitude-longitude radiance image with its sampling distribution.
#[derive(Clone, PartialEq)]
pub struct SkyMap {
    raster: Raster,
    /// Rows of cells: `height - 1`, or 1 for an image one row high.
    cell_rows: usize,
    /// The cells' distribution (`width x cell_rows`).
    distribution: Distribution2D,
    /// `int L dw` over the sphere, per channel ([`SkyMap::integral`]).
    integral: Vec3A,
    /// A hash of the texels, for telling renders apart ([`std::fmt::Debug`]).
    hash: u64,
}

impl std::fmt::Debug for SkyMap {
    /// The size and a hash of the texels: a render's fingerprint reads it, and a map of a
    /// million texels should not be printed.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "SkyMap({}x{}, {:016x})",
            self.raster.width, self.raster.height, self.hash
        )
    }
}

impl SkyMap {
    /// The map of `raster`, with its distribution. 8 bytes per cell for the distribution and
    /// 12 per texel for the image.
    pub fn new(raster: Raster) -> Self {
        let (w, h) = (raster.width, raster.height);
        let cell_rows = (h - 1).max(1);
        let row = |j: usize| j.min(h - 1);
        // The four corners of cell (c, r): columns c and c + 1 (wrapping), rows r and r + 1.
        let corners = |c: usize, r: usize| {
            let (c1, r1) = ((c + 1) % w, row(r + 1));
            [
                raster.at(c, row(r)),
                raster.at(c1, row(r)),
                raster.at(c, r1),
                raster.at(c1, r1),
            ]
        };
        let theta = |r: usize| PI * r as f64 / cell_rows as f64;
        let band = |r: usize| theta(r).cos() - theta(r + 1).cos();
        let distribution = Distribution2D::new(w, cell_rows, |c, r| {
            corners(c, r).iter().map(|&t| luminance(t)).sum::<f64>() / 4.0 * band(r)
        });
        // int L dw: each cell's mean over its solid angle (2 pi / w) * band.
        let mut integral = [0.0f64; 3];
        for r in 0..cell_rows {
            for c in 0..w {
                for t in corners(c, r) {
                    for (s, v) in integral.iter_mut().zip(t) {
                        *s += v as f64 / 4.0 * band(r) * 2.0 * PI / w as f64;
                    }
                }
            }
        }
        let hash = raster.texels.iter().flatten().fold(
            0xcbf2_9ce4_8422_2325u64 ^ (w as u64) << 32 ^ h as u64,
            |h, c| (h ^ c.to_bits() as u64).wrapping_mul(0x0000_0100_0000_01b3),
        );
        SkyMap {
            raster,
            cell_rows,
            distribution,
            integral: Vec3A::new(integral[0] as f32, integral[1] as f32, integral[2] as f32),
            hash,
        }
    }

    /// The image.
    pub fn raster(&self) -> &Raster {
        &self.raster
    }

    /// `int L dw` over the sphere, per channel (the cells' means over their solid angles: the
    /// bilinear image's integral, within the variation of `sin(theta)` across a row).
    pub fn integral(&self) -> Vec3A {
        self.integral
    }

    /// The largest channel of any texel.
    pub fn max_radiance(&self) -> f64 {
        self.raster
            .texels
            .iter()
            .flatten()
            .fold(0.0f32, |m, &c| m.max(c)) as f64
    }

    /// The radiance at `(u, v)`, bilinear between texels, `u` wrapping and `v` clamped.
    #[inline]
    pub fn eval(&self, u: f32, v: f32) -> Vec3A {
        let (w, h) = (self.raster.width, self.raster.height);
        let x = u * w as f32 - 0.5;
        let fx0 = x.floor();
        let fx = x - fx0;
        let c0 = (fx0 as i64).rem_euclid(w as i64) as usize;
        let c1 = (c0 + 1) % w;
        let y = (v * (h - 1) as f32).clamp(0.0, (h - 1) as f32);
        let r0 = (y as usize).min(h.saturating_sub(2));
        let r1 = (r0 + 1).min(h - 1);
        let fy = (y - r0 as f32).clamp(0.0, 1.0);
        let t = |c, r| Vec3A::from(self.raster.at(c, r));
        let top = t(c0, r0) * (1.0 - fx) + t(c1, r0) * fx;
        let bottom = t(c0, r1) * (1.0 - fx) + t(c1, r1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// The cell holding `(u, v)`.
    #[inline]
    fn cell(&self, u: f32, v: f32) -> (usize, usize) {
        let w = self.raster.width;
        let c = ((u * w as f32 - 0.5).floor() as i64).rem_euclid(w as i64) as usize;
        let r = ((v * self.cell_rows as f32) as usize).min(self.cell_rows - 1);
        (c, r)
    }

    /// A point `(u, v)` drawn from `(u1, u2)` uniform in `[0, 1)^2`, with its density in
    /// `(u, v)`; `None` for a black map.
    #[inline]
    pub fn sample(&self, u1: f64, u2: f64) -> Option<((f32, f32), f32)> {
        let ((x, y), pdf) = self.distribution.sample(u1, u2)?;
        // Cells start half a texel along u.
        let u = (x + 0.5 / self.raster.width as f64).fract();
        Some(((u as f32, y as f32), pdf as f32))
    }

    /// The density in `(u, v)` with which [`SkyMap::sample`] picks `(u, v)`.
    #[inline]
    pub fn pdf(&self, u: f32, v: f32) -> f32 {
        let (c, r) = self.cell(u, v);
        self.distribution.pdf_cell(c, r) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(w: usize, h: usize, f: impl Fn(usize, usize) -> f32) -> SkyMap {
        let texels = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| [f(x, y); 3])
            .collect();
        SkyMap::new(Raster::new(w, h, texels).unwrap())
    }

    /// Texel centres give their texel; half-way between two columns, the mean; u wraps from
    /// the last column to the first; the first row is the zenith and the last the nadir.
    #[test]
    fn bilinear_lookup() {
        let m = map(4, 3, |x, y| (x + 10 * y) as f32);
        assert_eq!(m.eval(0.125, 0.0).x, 0.0);
        assert_eq!(m.eval(0.375, 0.5).x, 11.0);
        assert_eq!(m.eval(0.25, 0.0).x, 0.5);
        // Between the last column (u = 7/8) and the first (u = 1/8 + 1).
        assert_eq!(m.eval(0.0, 1.0).x, 0.5 * (3.0 + 0.0) + 20.0);
        assert_eq!(m.eval(0.625, 0.75).x, 2.0 + 15.0);
    }

    /// A constant map integrates to 4 pi L, whatever its size, and one texel of a 1x1 map is
    /// the whole sky.
    #[test]
    fn constant_maps_integrate_to_4_pi() {
        for (w, h) in [(1, 1), (2, 1), (8, 4), (3, 7)] {
            let m = map(w, h, |_, _| 2.0);
            let i = m.integral().x as f64;
            assert!((i - 8.0 * PI).abs() < 1e-4, "{w}x{h}: {i}");
            assert_eq!(m.eval(0.3, 0.9).x, 2.0);
        }
    }

    /// Sampled points have the density `pdf` reports, and a black map cannot be sampled.
    #[test]
    fn sample_and_pdf_agree() {
        let m = map(5, 4, |x, y| ((x * 7 + y * 3) % 4) as f32);
        for (u1, u2) in [(0.1, 0.2), (0.7, 0.95), (0.999, 0.5), (0.3, 0.01)] {
            let ((u, v), pdf) = m.sample(u1, u2).unwrap();
            assert!((0.0..1.0).contains(&u) && (0.0..=1.0).contains(&v));
            assert_eq!(m.pdf(u, v), pdf, "({u1}, {u2}) -> ({u}, {v})");
        }
        assert!(map(3, 3, |_, _| 0.0).sample(0.5, 0.5).is_none());
    }
}
