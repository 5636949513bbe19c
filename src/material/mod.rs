//! The closed set of materials. Each variant lives in its own file; [`Material`] dispatches by
//! `match`.
//!
//! Directions follow pbrt's convention: `wo` points from the surface towards the viewer, `wi`
//! from the surface towards the light; both are unit vectors; `n` is the unit normal on the
//! side of `wo`.

pub mod bsdf;
mod bsdf_sample;
mod coating;
pub mod conductor;
pub mod microfacet;
mod mirror;
mod model;
pub mod phong;
pub mod plastic;
pub mod rough_conductor;
pub mod rough_dielectric;
pub mod rough_plastic;
mod transmissive;

pub use bsdf::{Bsdf, BsdfSample};
pub use coating::{Coating, diffuse_fresnel_reflectance};
pub use mirror::Mirror;
pub use model::Model;
pub use phong::{Phong, reflect};
pub use transmissive::{Refraction, Transmissive, fresnel_dielectric};

use conductor::Conductor;
use glam::Vec3A;

/// A prepared material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Diffuse plus glossy reflection (the course's Phong model).
    Phong(Phong),
    /// Perfect specular reflection, tinted.
    Mirror(Mirror),
    /// A smooth metal: specular reflection weighted by its Fresnel term.
    Conductor(conductor::Conductor),
    /// Perfect specular refraction (Snell), tinted; total internal reflection when needed.
    Transmissive(Transmissive),
    /// A material given by its BSDF: rough metals and dielectrics, and plastics.
    Bsdf(Bsdf),
}

impl Material {
    /// The diffuse coefficient `kd` used by the ambient term (Eq. 2), if the material has one.
    ///
    /// Only Phong reflects light arriving from every direction, so only Phong answers; the
    /// others answer `None` (the course's framework printed a warning and returned -1 instead).
    #[inline]
    pub fn diffuse_coefficient(&self) -> Option<Vec3A> {
        match self {
            Material::Phong(p) => Some(p.kd),
            Material::Mirror(_)
            | Material::Conductor(_)
            | Material::Transmissive(_)
            | Material::Bsdf(_) => None,
        }
    }

    /// True for materials that let light through (smooth and rough glass): rays cross them.
    #[inline]
    pub fn transmits(&self) -> bool {
        match self {
            Material::Transmissive(_) => true,
            Material::Bsdf(b) => b.transmits(),
            Material::Phong(_) | Material::Mirror(_) | Material::Conductor(_) => false,
        }
    }

    /// The colour a denoiser's albedo layer expects of the material (OIDN's and Mitsuba's
    /// `albedo` AOV): the diffuse reflectance of Phong and the plastics, the tint of mirrors
    /// and glass (a rough dielectric's transmittance), a metal's reflectance at normal
    /// incidence (its Fresnel term at `cos = 1` times its `specular_reflectance`).
    pub fn albedo(&self) -> Vec3A {
        let metal = |m: &Conductor| {
            let f = |c: usize| conductor::fresnel_conductor(1.0, m.eta[c], m.k[c]);
            Vec3A::new(f(0), f(1), f(2)) * m.specular_reflectance
        };
        match self {
            Material::Phong(p) => p.kd,
            Material::Mirror(m) => m.color,
            Material::Conductor(m) => metal(m),
            Material::Transmissive(g) => g.color,
            Material::Bsdf(Bsdf::RoughConductor(b)) => metal(&b.metal),
            Material::Bsdf(Bsdf::RoughDielectric(b)) => b.specular_transmittance,
            Material::Bsdf(Bsdf::RoughPlastic(b)) => b.coating.diffuse_reflectance,
            Material::Bsdf(Bsdf::Plastic(b)) => b.coating.diffuse_reflectance,
        }
    }

    /// The material's kind as scene files name it (for replays and firefly reports).
    pub fn kind(&self) -> &'static str {
        match self {
            Material::Phong(_) => "Phong",
            Material::Mirror(_) => "Mirror",
            Material::Conductor(_) => "Conductor",
            Material::Transmissive(_) => "Transmissive",
            Material::Bsdf(b) => b.kind(),
        }
    }

    /// True for materials that only scatter into one direction (mirror, metal, glass).
    #[inline]
    pub fn is_specular(&self) -> bool {
        matches!(
            self,
            Material::Mirror(_) | Material::Conductor(_) | Material::Transmissive(_)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The assignment's `getDiffuseCoefficient()`: `kd` for Phong, nothing (and no warning) for
    /// the others.
    #[test]
    fn diffuse_coefficient_of_each_material() {
        let kd = Vec3A::new(0.7, 0.2, 0.3);
        let phong = Material::Phong(Phong {
            kd,
            ks: Vec3A::splat(0.5),
            shininess: 10.0,
        });
        assert_eq!(phong.diffuse_coefficient(), Some(kd));
        assert!(!phong.is_specular());
        let mirror = Material::Mirror(Mirror { color: Vec3A::ONE });
        let glass = Material::Transmissive(Transmissive {
            ior: 1.5,
            color: Vec3A::ONE,
        });
        for m in [mirror, glass] {
            assert_eq!(m.diffuse_coefficient(), None);
            assert!(m.is_specular());
        }
    }
}
