//! The rendered image: linear RGB radiance per pixel.

use glam::Vec3A;

/// A linear-radiance image, row-major, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels.
    pub pixels: Vec<Vec3A>,
}

impl Image {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Image {
            width,
            height,
            pixels: vec![Vec3A::ZERO; width as usize * height as usize],
        }
    }

    /// The pixel at `(col, row)`.
    #[inline]
    pub fn get(&self, col: u32, row: u32) -> Vec3A {
        self.pixels[(row * self.width + col) as usize]
    }

    /// Mean of each channel.
    pub fn mean(&self) -> Vec3A {
        let s: glam::DVec3 = self.pixels.iter().map(|p| p.as_dvec3()).sum();
        (s / self.pixels.len().max(1) as f64).as_vec3a()
    }

    /// True if every channel of every pixel is finite.
    pub fn all_finite(&self) -> bool {
        self.pixels.iter().all(|p| p.is_finite())
    }

    /// The same image mirrored left-right.
    pub fn flipped_horizontally(&self) -> Image {
        let mut out = self.clone();
        for row in 0..self.height {
            for col in 0..self.width {
                out.pixels[(row * self.width + col) as usize] = self.get(self.width - 1 - col, row);
            }
        }
        out
    }
}
