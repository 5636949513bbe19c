//! Perfectly refracting dielectrics.

use super::phong::reflect;
use glam::Vec3A;

/// A perfect refractor with index of refraction `ior` (outside is air, index 1) whose
/// transmitted radiance is tinted by `color`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transmissive {
    /// Index of refraction of the inside, > 0.
    pub ior: f32,
    /// Tint per channel, in [0, inf).
    pub color: Vec3A,
}

/// Where light goes at a dielectric boundary.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refraction {
    /// The new direction (transmitted, or reflected under total internal reflection).
    pub wt: Vec3A,
    /// True when there is no refracted direction and `wt` is the mirror direction.
    pub total_internal_reflection: bool,
    /// `eta = n_incident / n_transmitted` used for Snell's law.
    pub eta: f32,
    /// `|cos|` of the incident angle.
    pub cos_i: f32,
}

impl Transmissive {
    /// Refract `wo` (pointing away from the surface) through the boundary with outward normal
    /// `n_out`. Entering from outside `eta = 1 / ior`; leaving, `eta = ior`. Returns the mirror
    /// direction, flagged, when `sin(theta_t) > 1` (total internal reflection).
    #[inline]
    pub fn refract(&self, wo: Vec3A, n_out: Vec3A) -> Refraction {
        let entering = wo.dot(n_out) > 0.0;
        let (eta, n) = if entering {
            (1.0 / self.ior, n_out)
        } else {
            (self.ior, -n_out)
        };
        let cos_i = wo.dot(n);
        // Snell: sin^2(theta_t) = eta^2 sin^2(theta_i).
        let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
        if sin2_t > 1.0 {
            return Refraction {
                wt: reflect(wo, n),
                total_internal_reflection: true,
                eta,
                cos_i,
            };
        }
        let cos_t = (1.0 - sin2_t).sqrt();
        let wt = (-wo * eta + (eta * cos_i - cos_t) * n).normalize();
        Refraction {
            wt,
            total_internal_reflection: false,
            eta,
            cos_i,
        }
    }
}

/// Unpolarised Fresnel reflectance of a dielectric boundary for incident cosine `cos_i` (> 0)
/// and relative index `eta = n_i / n_t`; 1 under total internal reflection.
#[inline]
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_par = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let r_perp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    0.5 * (r_par * r_par + r_perp * r_perp)
}
