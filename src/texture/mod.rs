//! The closed set of textures: a colour that varies over a surface, looked up at a hit's
//! texture coordinates `(u, v)` (`Geometry::uv`, in the accelerator's layer) before its material is
//! evaluated. Each variant lives in its own file; [`Texture::eval`] dispatches by `match`.
//!
//! Every texture first maps `(u, v)` by its [`UvTransform`] (Mitsuba 3's `to_uv`).

mod checkerboard;
mod image;

pub use checkerboard::Checkerboard;
pub use image::{ImageTexture, TexelFilter, Wrap, mip_levels};

use glam::{Vec2, Vec3A};

/// An affine map of texture coordinates: scale, then rotate (degrees, counter-clockwise in
/// `(u, v)`), then offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform {
    /// Factors on `u` and `v`.
    pub scale: Vec2,
    /// Rotation in degrees.
    pub rotate: f32,
    /// Added last.
    pub offset: Vec2,
}

impl UvTransform {
    /// The identity.
    pub const IDENTITY: UvTransform = UvTransform {
        scale: Vec2::ONE,
        rotate: 0.0,
        offset: Vec2::ZERO,
    };

    /// The map of `uv`.
    #[inline]
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let s = uv * self.scale;
        let r = if self.rotate == 0.0 {
            s
        } else {
            let (sin, cos) = self.rotate.to_radians().sin_cos();
            Vec2::new(cos * s.x - sin * s.y, sin * s.x + cos * s.y)
        };
        r + self.offset
    }
}

/// How wide one camera sample's share of the image is on a surface, from the camera alone
/// (pbrt-v4's `Camera::Approximate_dp_dxy`, isotropic): at a point `p` (render coordinates,
/// the camera at the origin) on a surface of unit normal `n`, `(spread |p| + base) / |cos|`, with
/// `cos` between the view direction and `n` (at least 1/20: grazing footprints stop growing).
/// Used for every hit, camera rays' and others', as pbrt does.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Footprint {
    /// Growth with distance: a perspective pixel's angle.
    pub spread: f32,
    /// Width at the camera: an orthographic pixel's height.
    pub base: f32,
}

impl Footprint {
    /// One sample's share when a pixel has `spp` (stratified: each covers its stratum), the
    /// pixel's over `sqrt(spp)`.
    #[inline]
    pub fn per_sample(self, spp: u32) -> Footprint {
        let k = 1.0 / (spp.max(1) as f32).sqrt();
        Footprint {
            spread: self.spread * k,
            base: self.base * k,
        }
    }

    /// The width in scene units at `p` on a surface of unit normal `n`.
    #[inline]
    pub fn width(&self, p: Vec3A, n: Vec3A) -> f32 {
        let d = p.length();
        let cos = if d > 0.0 { (p.dot(n) / d).abs() } else { 1.0 };
        (self.spread * d + self.base) / cos.max(0.05)
    }
}

/// What a texture looks like.
#[derive(Clone, Debug, PartialEq)]
pub enum TextureKind {
    /// Two colours in alternating squares.
    Checkerboard(Checkerboard),
    /// An image.
    Image(ImageTexture),
}

/// A texture: its kind and the map of coordinates it is looked up through.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// What it looks like.
    pub kind: TextureKind,
    /// How `(u, v)` is mapped first.
    pub transform: UvTransform,
}

impl Texture {
    /// The colour at texture coordinates `uv`, for a footprint `width` wide in them (which
    /// the transform's scale widens).
    #[inline]
    pub fn eval(&self, uv: Vec2, width: f32) -> Vec3A {
        let uv = self.transform.apply(uv);
        match &self.kind {
            TextureKind::Checkerboard(c) => c.eval(uv),
            TextureKind::Image(i) => i.eval(uv, width * self.transform.scale.abs().max_element()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Scale, then a quarter turn, then the offset.
    #[test]
    fn uv_transform_order() {
        let t = UvTransform {
            scale: Vec2::new(2.0, 3.0),
            rotate: 90.0,
            offset: Vec2::new(0.5, 0.25),
        };
        let uv = t.apply(Vec2::new(1.0, 1.0));
        assert!(
            (uv - Vec2::new(-3.0 + 0.5, 2.0 + 0.25)).abs().max_element() < 1e-5,
            "{uv}"
        );
    }
}

/// The textures a material's parameters are read from, each in place of its constant: its
/// reflectance (Phong's `kd`, a mirror's or glass's `color`) and its specular coefficient
/// (Phong's `ks`). Looked up at a hit before the material is evaluated
/// ([`MaterialTextures::apply`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MaterialTextures {
    /// Phong's `kd`; `Mirror` and `Transmissive`'s `color`.
    pub reflectance: Option<Texture>,
    /// Phong's `ks`.
    pub specular: Option<Texture>,
}

impl MaterialTextures {
    /// True if no parameter is textured.
    pub fn is_empty(&self) -> bool {
        self.reflectance.is_none() && self.specular.is_none()
    }

    /// `material` with its textured parameters looked up at `uv` for a footprint `width` wide
    /// in texture coordinates, each channel clamped to [0, 1] (a reflectance); under the
    /// physically based model (`physical`) a Phong material whose `kd + ks` then exceeds 1 is
    /// scaled down as a constant one is at extraction.
    #[inline]
    pub fn apply(
        &self,
        material: &crate::material::Material,
        uv: Vec2,
        width: f32,
        physical: bool,
    ) -> crate::material::Material {
        use crate::material::Material;
        let at = |t: &Option<Texture>| {
            t.as_ref()
                .map(|t| t.eval(uv, width).clamp(Vec3A::ZERO, Vec3A::ONE))
        };
        let mut m = *material;
        match &mut m {
            Material::Phong(p) => {
                if let Some(kd) = at(&self.reflectance) {
                    p.kd = kd;
                }
                if let Some(ks) = at(&self.specular) {
                    p.ks = ks;
                }
                if physical && let Some(scaled) = p.energy_conserving() {
                    *p = scaled;
                }
            }
            Material::Mirror(mirror) => {
                if let Some(c) = at(&self.reflectance) {
                    mirror.color = c;
                }
            }
            Material::Transmissive(glass) => {
                if let Some(c) = at(&self.reflectance) {
                    glass.color = c;
                }
            }
            Material::Conductor(_) | Material::Bsdf(_) => {}
        }
        m
    }
}
