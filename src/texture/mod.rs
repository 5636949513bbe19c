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
    /// The mean colour over its image (or its two squares): an emitter's power reads it.
    pub fn mean(&self) -> Vec3A {
        match &self.kind {
            TextureKind::Checkerboard(c) => (c.color0 + c.color1) / 2.0,
            TextureKind::Image(i) => {
                let r = &i.raster;
                let sum = r.texels.iter().fold([0f64; 3], |acc, t| {
                    [
                        acc[0] + t[0] as f64,
                        acc[1] + t[1] as f64,
                        acc[2] + t[2] as f64,
                    ]
                });
                let n = r.texels.len().max(1) as f64;
                Vec3A::new(
                    (sum[0] / n) as f32,
                    (sum[1] / n) as f32,
                    (sum[2] / n) as f32,
                )
            }
        }
    }

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

/// The textures a material's parameters are read from, each in place of its constant. Looked
/// up at a hit before the material is evaluated ([`MaterialTextures::apply`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MaterialTextures {
    /// Phong's `kd`; `Mirror` and `Transmissive`'s `color`; the plastics'
    /// `diffuse_reflectance`.
    pub reflectance: Option<Texture>,
    /// Phong's `ks`; the conductors', rough dielectric's and plastics' `specular_reflectance`.
    pub specular: Option<Texture>,
    /// The rough dielectric's `specular_transmittance`.
    pub transmittance: Option<Texture>,
    /// A rough conductor's or dielectric's roughness along the tangent (`alpha_u`, or `alpha`
    /// with [`MaterialTextures::alpha_v`] the same texture): the texture's luminance.
    pub alpha_u: Option<Texture>,
    /// Its roughness across the tangent (`alpha_v`).
    pub alpha_v: Option<Texture>,
    /// A tangent-space normal map (Mitsuba 3's `normalmap`): each texel `c` is the shading
    /// normal `2 c - 1` in the frame of the surface's tangent, bitangent and normal.
    pub normal_map: Option<Texture>,
}

impl MaterialTextures {
    /// True if nothing is textured.
    pub fn is_empty(&self) -> bool {
        !self.has_parameters() && self.normal_map.is_none()
    }

    /// True if a parameter other than the normal is textured (the material is looked up at
    /// each hit).
    #[inline]
    pub fn has_parameters(&self) -> bool {
        self.reflectance.is_some()
            || self.specular.is_some()
            || self.transmittance.is_some()
            || self.alpha_u.is_some()
            || self.alpha_v.is_some()
    }

    /// True if only the reflectance (Phong's `kd`) is textured: no other parameter, no normal
    /// map.
    pub fn only_reflectance(&self) -> bool {
        // (Every field named, so that a new one is not forgotten here.)
        let MaterialTextures {
            reflectance,
            specular,
            transmittance,
            alpha_u,
            alpha_v,
            normal_map,
        } = self;
        reflectance.is_some()
            && specular.is_none()
            && transmittance.is_none()
            && alpha_u.is_none()
            && alpha_v.is_none()
            && normal_map.is_none()
    }

    /// The shading normal the normal map gives at `uv` for a footprint `width` wide, in the
    /// local frame (`z` the surface's normal, `x` its tangent): `2 c - 1` for the map's
    /// colour `c`, normalised; `+z` where that has no length. `None` without a map.
    #[inline]
    pub fn normal(&self, uv: Vec2, width: f32) -> Option<Vec3A> {
        let map = self.normal_map.as_ref()?;
        let n = map.eval(uv, width) * 2.0 - Vec3A::ONE;
        Some(n.try_normalize().unwrap_or(Vec3A::Z))
    }

    /// `material` with its textured parameters looked up at `uv` for a footprint `width` wide
    /// in texture coordinates: each colour channel clamped to [0, 1] (a reflectance), each
    /// roughness (luminance) to [1e-4, 1]. Under the physically based model (`physical`) a
    /// Phong material whose `kd + ks` then exceeds 1 is scaled down as a constant one is at
    /// extraction.
    #[inline]
    pub fn apply(
        &self,
        material: &crate::material::Material,
        uv: Vec2,
        width: f32,
        physical: bool,
    ) -> crate::material::Material {
        use crate::material::microfacet::{MIN_ALPHA, Microfacet};
        use crate::material::{Bsdf, Material};
        let at = |t: &Option<Texture>| {
            t.as_ref()
                .map(|t| t.eval(uv, width).clamp(Vec3A::ZERO, Vec3A::ONE))
        };
        let set = |c: &mut Vec3A, t: &Option<Texture>| {
            if let Some(v) = at(t) {
                *c = v;
            }
        };
        // Roughness: the luminance (Rec. 709 weights, as Mitsuba's one-channel lookup); a
        // grey texel's own value, exactly.
        let rough = |m: &mut Microfacet| {
            let lum = |t: &Option<Texture>| {
                t.as_ref().map(|t| {
                    let c = t.eval(uv, width);
                    let y = if c.x == c.y && c.y == c.z {
                        c.x
                    } else {
                        0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
                    };
                    y.clamp(MIN_ALPHA, 1.0)
                })
            };
            let u = lum(&self.alpha_u);
            // An isotropic `alpha` is one texture on both axes: looked up once.
            let v = if self.alpha_v == self.alpha_u {
                u
            } else {
                lum(&self.alpha_v)
            };
            if let Some(a) = u {
                m.alpha_x = a;
            }
            if let Some(a) = v {
                m.alpha_y = a;
            }
        };
        // A plastic's coating over its textured base, its own reflection textured.
        let retint = |c: &crate::material::Coating| {
            c.retinted(
                at(&self.reflectance).unwrap_or(c.diffuse_reflectance),
                at(&self.specular).unwrap_or(c.specular_reflectance),
            )
        };
        let mut m = *material;
        match &mut m {
            Material::Phong(p) => {
                set(&mut p.kd, &self.reflectance);
                set(&mut p.ks, &self.specular);
                if physical && let Some(scaled) = p.energy_conserving() {
                    *p = scaled;
                }
            }
            Material::Mirror(mirror) => set(&mut mirror.color, &self.reflectance),
            Material::Transmissive(glass) => set(&mut glass.color, &self.reflectance),
            Material::Conductor(c) => set(&mut c.specular_reflectance, &self.specular),
            Material::Bsdf(Bsdf::RoughConductor(b)) => {
                set(&mut b.metal.specular_reflectance, &self.specular);
                rough(&mut b.microfacet);
            }
            Material::Bsdf(Bsdf::RoughDielectric(b)) => {
                set(&mut b.specular_reflectance, &self.specular);
                set(&mut b.specular_transmittance, &self.transmittance);
                rough(&mut b.microfacet);
            }
            Material::Bsdf(Bsdf::RoughPlastic(b)) => b.coating = retint(&b.coating),
            Material::Bsdf(Bsdf::Plastic(b)) => b.coating = retint(&b.coating),
        }
        m
    }
}
