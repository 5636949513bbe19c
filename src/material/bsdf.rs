//! The closed set of materials given by a BSDF in the local shading frame: `eval`, `sample`
//! and `pdf`, as pbrt-v4's BxDFs. Each variant lives in its own file; [`Bsdf`] dispatches by
//! `match`.
//!
//! The frame's `z` is the surface's outward shading normal, `x` its tangent (along which
//! `alpha_u` applies). A dielectric tells the sides apart by the sign of `wo.z`; the others
//! are two-sided, as every rtis material: seen from below, they reflect as seen from above.
//!
//! Adding a BSDF touches three places: its file here, this file (a variant and an arm in each
//! `match`, which the compiler names), and the scene file's `MaterialDesc` with its conversion.

pub use super::bsdf_sample::BsdfSample;
use super::microfacet::Microfacet;
use super::plastic::Plastic;
use super::rough_conductor::RoughConductor;
use super::rough_dielectric::RoughDielectric;
use super::rough_plastic::RoughPlastic;
use glam::Vec3A;

/// A material given by its BSDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Bsdf {
    /// A rough metal (Mitsuba 3's `roughconductor`).
    RoughConductor(RoughConductor),
    /// A rough interface between two dielectrics (`roughdielectric`).
    RoughDielectric(RoughDielectric),
    /// A diffuse base under a rough dielectric coating (`roughplastic`).
    RoughPlastic(RoughPlastic),
    /// A diffuse base under a smooth dielectric coating (`plastic`).
    Plastic(Plastic),
}

impl Bsdf {
    /// The BSDF's kind as scene files name it.
    pub fn kind(&self) -> &'static str {
        match self {
            Bsdf::RoughConductor(_) => "RoughConductor",
            Bsdf::RoughDielectric(_) => "RoughDielectric",
            Bsdf::RoughPlastic(_) => "RoughPlastic",
            Bsdf::Plastic(_) => "Plastic",
        }
    }

    /// `f(wo, wi) |cos(theta_i)|` without delta lobes.
    #[inline]
    pub fn eval(&self, wo: Vec3A, wi: Vec3A) -> Vec3A {
        let (wo, wi) = self.facing(wo, wi);
        match self {
            Bsdf::RoughConductor(b) => b.eval(wo, wi),
            Bsdf::RoughDielectric(b) => b.eval(wo, wi),
            Bsdf::RoughPlastic(b) => b.eval(wo, wi),
            Bsdf::Plastic(b) => b.eval(wo, wi),
        }
    }

    /// The density per solid angle with which [`Bsdf::sample`] draws `wi` from its non-delta
    /// lobes.
    #[inline]
    pub fn pdf(&self, wo: Vec3A, wi: Vec3A) -> f32 {
        let (wo, wi) = self.facing(wo, wi);
        match self {
            Bsdf::RoughConductor(b) => b.pdf(wo, wi),
            Bsdf::RoughDielectric(b) => b.pdf(wo, wi),
            Bsdf::RoughPlastic(b) => b.pdf(wo, wi),
            Bsdf::Plastic(b) => b.pdf(wo, wi),
        }
    }

    /// A direction for the viewer `wo` from the uniform numbers `uc` (which lobe) and `(u1,
    /// u2)`; `None` when it carries nothing.
    #[inline]
    pub fn sample(&self, wo: Vec3A, uc: f32, u1: f32, u2: f32) -> Option<BsdfSample> {
        let below = wo.z < 0.0 && !self.transmits();
        let (up, _) = self.facing(wo, wo);
        let mut s = match self {
            Bsdf::RoughConductor(b) => b.sample(up, u1, u2),
            Bsdf::RoughDielectric(b) => b.sample(up, uc, u1, u2),
            Bsdf::RoughPlastic(b) => b.sample(up, uc, u1, u2),
            Bsdf::Plastic(b) => b.sample(up, uc, u1, u2),
        }?;
        // A two-sided material seen from below: turn wi back to wo's side.
        if below {
            s.wi.z = -s.wi.z;
        }
        Some(s)
    }

    /// The distribution of microfacet normals of a rough material; `None` for the smooth
    /// plastic.
    pub fn microfacet(&self) -> Option<&Microfacet> {
        match self {
            Bsdf::RoughConductor(b) => Some(&b.microfacet),
            Bsdf::RoughDielectric(b) => Some(&b.microfacet),
            Bsdf::RoughPlastic(b) => Some(&b.microfacet),
            Bsdf::Plastic(_) => None,
        }
    }

    /// [`Bsdf::microfacet`], to change (how it is sampled).
    pub fn microfacet_mut(&mut self) -> Option<&mut Microfacet> {
        match self {
            Bsdf::RoughConductor(b) => Some(&mut b.microfacet),
            Bsdf::RoughDielectric(b) => Some(&mut b.microfacet),
            Bsdf::RoughPlastic(b) => Some(&mut b.microfacet),
            Bsdf::Plastic(_) => None,
        }
    }

    /// The material's name in scene files.
    pub fn name(&self) -> &'static str {
        match self {
            Bsdf::RoughConductor(_) => "RoughConductor",
            Bsdf::RoughDielectric(_) => "RoughDielectric",
            Bsdf::RoughPlastic(_) => "RoughPlastic",
            Bsdf::Plastic(_) => "Plastic",
        }
    }

    /// True if light from the far side of the surface can reach the viewer (a dielectric).
    #[inline]
    pub fn transmits(&self) -> bool {
        matches!(self, Bsdf::RoughDielectric(_))
    }

    /// `wo` and `wi` as the material sees them: for a two-sided material seen from below,
    /// both mirrored through the surface.
    #[inline]
    fn facing(&self, wo: Vec3A, wi: Vec3A) -> (Vec3A, Vec3A) {
        if wo.z < 0.0 && !self.transmits() {
            let flip = Vec3A::new(1.0, 1.0, -1.0);
            (wo * flip, wi * flip)
        } else {
            (wo, wi)
        }
    }
}
