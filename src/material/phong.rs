//! The Phong material in the course's convention and in a physically based normalisation.

use glam::Vec3A;
use std::f32::consts::PI;

/// Phong reflection: diffuse coefficient `kd`, specular coefficient `ks`, exponent `shininess`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phong {
    /// Diffuse coefficient, per channel, in [0, inf).
    pub kd: Vec3A,
    /// Specular coefficient, per channel, in [0, inf).
    pub ks: Vec3A,
    /// Phong exponent `s >= 0`.
    pub shininess: f32,
}

/// The mirror image of `w` about the unit normal `n`: `2 (n.w) n - w`.
#[inline]
pub fn reflect(w: Vec3A, n: Vec3A) -> Vec3A {
    2.0 * n.dot(w) * n - w
}

impl Phong {
    /// The course's reflectance `r(wi, wo) = kd (wi.n) + ks (wo.wr)^s`, with `wr` the mirror of
    /// `wi` about `n`.
    ///
    /// It is not a BRDF: the cosine `wi.n` is inside it, the diffuse lobe is not divided by pi
    /// and the specular lobe is not normalised, so it can reflect more than it receives (see
    /// `docs/transport.md`). Both cosines are clamped at 0: the original left `wo.wr`
    /// unclamped, which lights the back of an even exponent's lobe.
    #[inline]
    pub fn course_reflectance(&self, wi: Vec3A, wo: Vec3A, n: Vec3A) -> Vec3A {
        let cos_i = wi.dot(n).max(0.0);
        if self.ks == Vec3A::ZERO {
            return self.kd * cos_i;
        }
        let wr = reflect(wi, n);
        let cos_r = wo.dot(wr).max(0.0);
        self.kd * cos_i + self.ks * cos_r.powf(self.shininess)
    }

    /// True if the material reflects nothing (`kd = ks = 0`, as an emitter without a material).
    #[inline]
    pub fn is_black(&self) -> bool {
        self.kd == Vec3A::ZERO && self.ks == Vec3A::ZERO
    }

    /// This material scaled so that `kd + ks <= 1` in every channel, or `None` if it already
    /// is. The normalised Phong BRDF reflects at most `kd + ks` of the light it receives, so
    /// under the physically based model a sum above one would create energy, and a path tracer
    /// would diverge in a closed scene. Like pbrt, which clamps reflectances to [0, 1], rtis
    /// makes the material physical rather than refuse it.
    pub fn energy_conserving(&self) -> Option<Phong> {
        let sum = self.kd + self.ks;
        if sum.max_element() <= 1.0 {
            return None;
        }
        let k = Vec3A::ONE / sum.max(Vec3A::ONE);
        Some(Phong {
            kd: self.kd * k,
            ks: self.ks * k,
            ..*self
        })
    }

    /// The energy-conserving normalised Phong BRDF
    /// `f(wi, wo) = kd / pi + ks (s + 2) / (2 pi) (wo.wr)^s` (Lafortune and Willems 1994),
    /// zero when either direction is below the surface. Multiply by `wi.n` for the integrand.
    #[inline]
    pub fn brdf(&self, wi: Vec3A, wo: Vec3A, n: Vec3A) -> Vec3A {
        if wi.dot(n) <= 0.0 || wo.dot(n) <= 0.0 {
            return Vec3A::ZERO;
        }
        // A diffuse material skips the power: the specular term would add exactly 0.
        if self.ks == Vec3A::ZERO {
            return self.kd * (1.0 / PI);
        }
        let cos_r = wo.dot(reflect(wi, n)).max(0.0);
        self.kd * (1.0 / PI)
            + self.ks * ((self.shininess + 2.0) / (2.0 * PI) * cos_r.powf(self.shininess))
    }
}
