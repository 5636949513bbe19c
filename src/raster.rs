//! Images read as linear RGB: the environment light's map and textures.
//!
//! OpenEXR files hold linear values and are read as they are. PNG files (8 or 16 bits, grey or
//! colour, with or without alpha) and JPEG files hold sRGB-encoded values and are decoded with the sRGB
//! transfer function (IEC 61966-2-1), as Mitsuba 3 and pbrt-v4 decode them. Alpha is ignored.
//! A raster holds 12 bytes per texel (three `f32`); reading one needs about twice that at its
//! peak, plus the file's own decoded form.
//!
//! A side may be at most [`MAX_SIDE`] texels and an image at most [`MAX_TEXELS`] texels; a larger
//! one is refused before it is decoded, saying how much memory it would need.

use std::path::Path;

/// Largest number of texels a raster may have (2^28, 3 GiB as 12-byte texels).
pub const MAX_TEXELS: u64 = 1 << 28;
/// Largest width or height (2^16: texel coordinates stay exact in `f32` arithmetic).
pub const MAX_SIDE: u32 = 1 << 16;

/// A rectangle of linear RGB texels, row by row from the top.
#[derive(Clone, PartialEq)]
pub struct Raster {
    /// Texels per row (at least 1).
    pub width: usize,
    /// Rows (at least 1).
    pub height: usize,
    /// `width * height` texels, linear RGB, each channel finite and `>= 0`.
    pub texels: Vec<[f32; 3]>,
}

impl std::fmt::Debug for Raster {
    /// The size and a hash of the texels (what tells two renders apart), not the texels.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let hash = self
            .texels
            .iter()
            .flatten()
            .fold(0xcbf2_9ce4_8422_2325u64, |h, c| {
                (h ^ c.to_bits() as u64).wrapping_mul(0x0000_0100_0000_01b3)
            });
        write!(f, "Raster({}x{}, {hash:016x})", self.width, self.height)
    }
}

impl Raster {
    /// The raster of `texels`, checked: a size of at least 1x1 whose product is the number of
    /// texels, and finite, non-negative channels (the first bad texel is named).
    pub fn new(width: usize, height: usize, texels: Vec<[f32; 3]>) -> Result<Self, String> {
        if width == 0 || height == 0 || width * height != texels.len() {
            return Err(format!(
                "an image of {width}x{height} texels cannot hold {} texels",
                texels.len()
            ));
        }
        if let Some(i) = texels
            .iter()
            .position(|t| t.iter().any(|c| !c.is_finite() || *c < 0.0))
        {
            let t = texels[i];
            return Err(format!(
                "texel ({}, {}) (column, row from the top left) is ({}, {}, {}): a texel is \
                 finite and not negative",
                i % width,
                i / width,
                t[0],
                t[1],
                t[2]
            ));
        }
        Ok(Raster {
            width,
            height,
            texels,
        })
    }

    /// The texel at column `x`, row `y`.
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> [f32; 3] {
        self.texels[y * self.width + x]
    }
}

/// The sRGB transfer function's inverse: the linear value of an encoded value `c` in [0, 1].
#[inline]
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Read the image at `path` (OpenEXR, or PNG or JPEG decoded from sRGB): the message names the reason
/// it cannot be read, without the path (the caller places it).
pub fn load(path: &Path) -> Result<Raster, String> {
    load_with(path, false)
}

/// [`load`]; with `raw`, PNG and JPEG values are taken as they are stored (scaled to [0, 1]), not
/// decoded from sRGB: for data such as roughness or normal maps.
pub fn load_with(path: &Path, raw: bool) -> Result<Raster, String> {
    use image::{DynamicImage, ImageReader, Limits};
    let reader = ImageReader::open(path)
        .map_err(|e| format!("cannot read image {}: {e}", path.display()))?
        .with_guessed_format()
        .map_err(|e| format!("cannot read image {}: {e}", path.display()))?;
    let (w, h) = reader
        .into_dimensions()
        .map_err(|e| format!("cannot read image {}: {e}", path.display()))?;
    let texels = w as u64 * h as u64;
    if texels > MAX_TEXELS || w > MAX_SIDE || h > MAX_SIDE {
        return Err(format!(
            "image {} is {w}x{h}: as linear RGB it needs {} MiB; the limit is {} MiB \
             ({MAX_TEXELS} texels) and {MAX_SIDE} texels a side",
            path.display(),
            (texels * 12) >> 20,
            (MAX_TEXELS * 12) >> 20
        ));
    }
    let mut reader = ImageReader::open(path)
        .and_then(|r| r.with_guessed_format())
        .map_err(|e| format!("cannot read image {}: {e}", path.display()))?;
    let mut limits = Limits::default();
    limits.max_alloc = Some(MAX_TEXELS * 16);
    reader.limits(limits);
    let image = reader
        .decode()
        .map_err(|e| format!("cannot decode image {}: {e}", path.display()))?;
    let linear = matches!(
        image,
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_)
    );
    // The decoded image is dropped once converted (unless it was already linear RGB).
    let rgb = image.into_rgb32f().into_raw();
    let decode = |c: f32| if linear || raw { c } else { srgb_to_linear(c) };
    let texels = rgb
        .chunks_exact(3)
        .map(|p| [decode(p[0]), decode(p[1]), decode(p[2])])
        .collect();
    Raster::new(w as usize, h as usize, texels)
        .map_err(|why| format!("image {}: {why}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sRGB decode of known 8-bit codes (IEC 61966-2-1): 0, the linear segment's end, the
    /// middle and the top.
    #[test]
    fn srgb_decode() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(10.0 / 255.0) - 0.003_035_27).abs() < 1e-7);
        assert!((srgb_to_linear(128.0 / 255.0) - 0.215_860_5).abs() < 1e-6);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
    }

    /// A NaN or negative texel is refused, naming it.
    #[test]
    fn bad_texels_are_named() {
        let e = Raster::new(2, 1, vec![[0.0; 3], [1.0, f32::NAN, 0.0]]).unwrap_err();
        assert!(e.contains("texel (1, 0)"), "{e}");
        assert!(Raster::new(1, 1, vec![[-1.0, 0.0, 0.0]]).is_err());
        assert!(Raster::new(2, 2, vec![[0.0; 3]]).is_err());
    }
}
