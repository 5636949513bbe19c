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
    /// Bilinear in the two MIP levels whose texels best match the hit's footprint, blended
    /// (pbrt-v4's `Trilinear`): a far, dense image averages instead of aliasing.
    Trilinear,
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
#[derive(Clone, Debug)]
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
    /// Levels 1, 2, ... of the MIP pyramid (each half the last, rounded up, by 2x2 box
    /// averages), built for [`TexelFilter::Trilinear`] only; empty otherwise.
    pub mips: Arc<Vec<Raster>>,
}

/// Two textures are the same if they read the same texels (shared: an image is read once per
/// scene) in the same way; the texels are not compared one by one.
impl PartialEq for ImageTexture {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.raster, &other.raster)
            && Arc::ptr_eq(&self.mips, &other.mips)
            && self.filter == other.filter
            && self.wrap == other.wrap
            && self.raw == other.raw
    }
}

/// A texel coordinate `x` (texel widths from the image's edge) as the floor's integer and the
/// fraction above it: non-finite coordinates (a degenerate hit) read texel 0, and the rest are
/// held within 1e12 texels (where `f64` no longer tells texels apart anyway), so that the
/// integers and their neighbours never overflow.
#[inline]
fn texel_coordinate(x: f64) -> (i64, f32) {
    if !x.is_finite() {
        return (0, 0.0);
    }
    let x = x.clamp(-1e12, 1e12);
    let x0 = x.floor();
    (x0 as i64, (x - x0) as f32)
}

/// The MIP levels above `raster`: each half the one below (rounded up) on each side, its texel
/// the mean of the (up to) four below it, down to 1x1. A third more memory than the image.
pub fn mip_levels(raster: &Raster) -> Vec<Raster> {
    let mut levels: Vec<Raster> = Vec::new();
    loop {
        let below = levels.last().unwrap_or(raster);
        let (w, h) = (below.width, below.height);
        if w == 1 && h == 1 {
            return levels;
        }
        let (w2, h2) = (w.div_ceil(2), h.div_ceil(2));
        let mut texels = Vec::with_capacity(w2 * h2);
        for j in 0..h2 {
            for i in 0..w2 {
                let mut sum = [0.0f32; 3];
                let mut n = 0.0;
                for y in 2 * j..(2 * j + 2).min(h) {
                    for x in 2 * i..(2 * i + 2).min(w) {
                        let t = below.at(x, y);
                        (0..3).for_each(|c| sum[c] += t[c]);
                        n += 1.0;
                    }
                }
                texels.push(sum.map(|s| s / n));
            }
        }
        let next = Raster::new(w2, h2, texels).expect("a level of at least 1x1 texels");
        levels.push(next);
    }
}

impl ImageTexture {
    /// The colour at `uv`, for a footprint `width` wide in texture coordinates (read by
    /// [`TexelFilter::Trilinear`] only).
    #[inline]
    pub fn eval(&self, uv: Vec2, width: f32) -> Vec3A {
        match self.filter {
            TexelFilter::Nearest => {
                let (w, h) = (self.raster.width, self.raster.height);
                let (i, _) = texel_coordinate(uv.x as f64 * w as f64);
                let (j, _) = texel_coordinate(uv.y as f64 * h as f64);
                Vec3A::from(self.raster.at(self.wrap.index(i, w), self.wrap.index(j, h)))
            }
            TexelFilter::Bilinear => bilinear(&self.raster, self.wrap, uv),
            TexelFilter::Trilinear => {
                // The level whose texels are as wide as the footprint: log2 of the footprint in
                // level-0 texels (of the longer side), between the finest and the coarsest.
                let texels = width * self.raster.width.max(self.raster.height) as f32;
                let top = self.mips.len() as f32;
                let level = if texels > 1.0 {
                    texels.log2().min(top)
                } else {
                    0.0
                };
                let l0 = level.floor() as usize;
                let t = level - l0 as f32;
                let at = |l: usize| match l {
                    0 => &*self.raster,
                    _ => &self.mips[(l - 1).min(self.mips.len() - 1)],
                };
                let a = bilinear(at(l0), self.wrap, uv);
                if t == 0.0 {
                    a
                } else {
                    a * (1.0 - t) + bilinear(at(l0 + 1), self.wrap, uv) * t
                }
            }
        }
    }
}

/// `raster` at `uv`, bilinear between the texel centres, beyond the edges by `wrap`.
#[inline]
fn bilinear(raster: &Raster, wrap: Wrap, uv: Vec2) -> Vec3A {
    let (w, h) = (raster.width, raster.height);
    let texel = |i: i64, j: i64| Vec3A::from(raster.at(wrap.index(i, w), wrap.index(j, h)));
    let (i, fx) = texel_coordinate(uv.x as f64 * w as f64 - 0.5);
    let (j, fy) = texel_coordinate(uv.y as f64 * h as f64 - 0.5);
    let top = texel(i, j) * (1.0 - fx) + texel(i + 1, j) * fx;
    let bottom = texel(i, j + 1) * (1.0 - fx) + texel(i + 1, j + 1) * fx;
    top * (1.0 - fy) + bottom * fy
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(filter: TexelFilter, wrap: Wrap) -> ImageTexture {
        // A 2x2 image: 0 and 1 on top, 2 and 3 below.
        let texels = (0..4).map(|i| [i as f32; 3]).collect();
        let raster = Raster::new(2, 2, texels).unwrap();
        ImageTexture {
            mips: Arc::new(mip_levels(&raster)),
            raster: Arc::new(raster),
            source: "test".into(),
            raw: false,
            filter,
            wrap,
        }
    }

    /// Trilinear: a footprint below a texel reads level 0 (bilinear); one as wide as the image
    /// reads its 1x1 top, the mean; half-way in log2 blends the two levels by half.
    #[test]
    fn trilinear_picks_the_level_of_the_footprint() {
        let t = image(TexelFilter::Trilinear, Wrap::Repeat);
        let uv = Vec2::new(0.25, 0.25);
        assert_eq!(t.eval(uv, 0.1), t.eval(uv, 0.0));
        assert_eq!(t.eval(uv, 0.1).x, 0.0);
        assert_eq!(t.eval(uv, 1.0).x, 1.5);
        assert_eq!(t.eval(uv, 100.0).x, 1.5);
        let half = t.eval(uv, std::f32::consts::SQRT_2 / 2.0).x;
        assert!((half - 0.75).abs() < 1e-5, "{half}");
        assert_eq!(mip_levels(&t.raster).len(), 1);
    }

    /// Texel centres give their texel; half-way between two, the mean; a quarter of the way,
    /// the weighted mean; the top row is at v = 0.
    #[test]
    fn bilinear_values_between_texels() {
        let t = image(TexelFilter::Bilinear, Wrap::Clamp);
        let at = |u: f32, v: f32| t.eval(Vec2::new(u, v), 0.0).x;
        assert_eq!(at(0.25, 0.25), 0.0);
        assert_eq!(at(0.75, 0.25), 1.0);
        assert_eq!(at(0.25, 0.75), 2.0);
        assert_eq!(at(0.5, 0.25), 0.5);
        assert_eq!(at(0.5, 0.5), 1.5);
        assert_eq!(at(0.375, 0.25), 0.25);
        let n = image(TexelFilter::Nearest, Wrap::Clamp);
        assert_eq!(n.eval(Vec2::new(0.49, 0.51), 0.0).x, 2.0);
    }

    /// Past the edges: repeat wraps to the other side, clamp keeps the edge, mirror reflects.
    #[test]
    fn wrap_modes_at_the_borders() {
        let at = |wrap, u: f32| {
            image(TexelFilter::Nearest, wrap)
                .eval(Vec2::new(u, 0.25), 0.0)
                .x
        };
        assert_eq!(at(Wrap::Repeat, 1.25), 0.0);
        assert_eq!(at(Wrap::Repeat, -0.25), 1.0);
        assert_eq!(at(Wrap::Clamp, 1.75), 1.0);
        assert_eq!(at(Wrap::Clamp, -3.0), 0.0);
        assert_eq!(at(Wrap::Mirror, 1.25), 1.0);
        assert_eq!(at(Wrap::Mirror, 1.75), 0.0);
        assert_eq!(at(Wrap::Mirror, -0.25), 0.0);
        // Bilinear across the seam: repeat blends the last column with the first.
        let t = image(TexelFilter::Bilinear, Wrap::Repeat);
        assert_eq!(t.eval(Vec2::new(0.0, 0.25), 0.0).x, 0.5);
        let t = image(TexelFilter::Bilinear, Wrap::Clamp);
        assert_eq!(t.eval(Vec2::new(0.0, 0.25), 0.0).x, 0.0);
        // Far and non-finite coordinates read a texel, never overflow: clamp holds the edge.
        assert_eq!(t.eval(Vec2::new(1e30, 0.25), 0.0).x, 1.0);
        assert_eq!(t.eval(Vec2::new(f32::NAN, f32::INFINITY), 0.0).x, 0.0);
        let r = image(TexelFilter::Bilinear, Wrap::Repeat);
        assert!(r.eval(Vec2::new(-1e30, 1e20), 0.0).is_finite());
    }
}
