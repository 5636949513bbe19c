//! Mitsuba 3's `bitmap`: an image looked up at `(u, v)`, with texel `(i, j)` centred at
//! `((i + 1/2) / w, (j + 1/2) / h)`: the image's top row at `v = 0`, its left column at
//! `u = 0`. Outside `[0, 1)` the coordinates repeat, clamp to the edge, or repeat mirrored.
//! Texels are linear RGB, 12 bytes each ([`crate::raster`]); an image used several times is
//! read once.

use crate::raster::Raster;
use glam::{Vec2, Vec3A};
use std::path::PathBuf;
use std::sync::Arc;

/// How texels are looked up between their centres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
pub enum TexelFilter {
    /// The texel the point falls in.
    Nearest,
    /// The four nearest texels, weighted by distance (Mitsuba's default).
    #[default]
    Bilinear,
}

/// What lies beyond the image's edges.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
pub enum Wrap {
    /// The image again (Mitsuba's default).
    #[default]
    Repeat,
    /// The edge texels, stretched.
    Clamp,
    /// The image again, mirrored every other time.
    Mirror,
}

impl Wrap {
    /// The texel index `i` of a side of `n` texels lands on.
    #[inline]
    pub fn index(self, i: i64, n: usize) -> usize {
        let n = n as i64;
        (match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m >= n { 2 * n - 1 - m } else { m }
            }
        }) as usize
    }
}

/// An image texture.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageTexture {
    /// The texels, shared by every texture that reads the same file.
    pub raster: Arc<Raster>,
    /// The file they were read from (for `rtis check`), or a label for an image made in code.
    pub source: PathBuf,
    /// PNG values taken as stored, not decoded from sRGB.
    pub raw: bool,
    /// Lookup between texel centres.
    pub filter: TexelFilter,
    /// Beyond the edges.
    pub wrap: Wrap,
}

impl ImageTexture {
    /// The colour at `uv`.
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Vec3A {
        let (w, h) = (self.raster.width, self.raster.height);
        let texel = |i: i64, j: i64| {
            Vec3A::from(self.raster.at(self.wrap.index(i, w), self.wrap.index(j, h)))
        };
        let x = uv.x as f64 * w as f64;
        let y = uv.y as f64 * h as f64;
        match self.filter {
            TexelFilter::Nearest => texel(x.floor() as i64, y.floor() as i64),
            TexelFilter::Bilinear => {
                let (x, y) = (x - 0.5, y - 0.5);
                let (x0, y0) = (x.floor(), y.floor());
                let (fx, fy) = ((x - x0) as f32, (y - y0) as f32);
                let (i, j) = (x0 as i64, y0 as i64);
                let top = texel(i, j) * (1.0 - fx) + texel(i + 1, j) * fx;
                let bottom = texel(i, j + 1) * (1.0 - fx) + texel(i + 1, j + 1) * fx;
                top * (1.0 - fy) + bottom * fy
            }
        }
    }

    /// The largest channel of any texel.
    pub fn max_value(&self) -> f32 {
        self.raster
            .texels
            .iter()
            .flatten()
            .fold(0.0, |m, &c| m.max(c))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(filter: TexelFilter, wrap: Wrap) -> ImageTexture {
        // A 2x2 image: 0 and 1 on top, 2 and 3 below.
        let texels = (0..4).map(|i| [i as f32; 3]).collect();
        ImageTexture {
            raster: Arc::new(Raster::new(2, 2, texels).unwrap()),
            source: "test".into(),
            raw: false,
            filter,
            wrap,
        }
    }

    /// Texel centres give their texel; half-way between two, the mean; a quarter of the way,
    /// the weighted mean; the top row is at v = 0.
    #[test]
    fn bilinear_values_between_texels() {
        let t = image(TexelFilter::Bilinear, Wrap::Clamp);
        let at = |u: f32, v: f32| t.eval(Vec2::new(u, v)).x;
        assert_eq!(at(0.25, 0.25), 0.0);
        assert_eq!(at(0.75, 0.25), 1.0);
        assert_eq!(at(0.25, 0.75), 2.0);
        assert_eq!(at(0.5, 0.25), 0.5);
        assert_eq!(at(0.5, 0.5), 1.5);
        assert_eq!(at(0.375, 0.25), 0.25);
        let n = image(TexelFilter::Nearest, Wrap::Clamp);
        assert_eq!(n.eval(Vec2::new(0.49, 0.51)).x, 2.0);
    }

    /// Past the edges: repeat wraps to the other side, clamp keeps the edge, mirror reflects.
    #[test]
    fn wrap_modes_at_the_borders() {
        let at = |wrap, u: f32| image(TexelFilter::Nearest, wrap).eval(Vec2::new(u, 0.25)).x;
        assert_eq!(at(Wrap::Repeat, 1.25), 0.0);
        assert_eq!(at(Wrap::Repeat, -0.25), 1.0);
        assert_eq!(at(Wrap::Clamp, 1.75), 1.0);
        assert_eq!(at(Wrap::Clamp, -3.0), 0.0);
        assert_eq!(at(Wrap::Mirror, 1.25), 1.0);
        assert_eq!(at(Wrap::Mirror, 1.75), 0.0);
        assert_eq!(at(Wrap::Mirror, -0.25), 0.0);
        // Bilinear across the seam: repeat blends the last column with the first.
        let t = image(TexelFilter::Bilinear, Wrap::Repeat);
        assert_eq!(t.eval(Vec2::new(0.0, 0.25)).x, 0.5);
        let t = image(TexelFilter::Bilinear, Wrap::Clamp);
        assert_eq!(t.eval(Vec2::new(0.0, 0.25)).x, 0.0);
    }
}
